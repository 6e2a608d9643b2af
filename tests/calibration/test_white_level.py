"""A light projection's clip is named the sensor's saturation only if the sensor's own clean frames stay under it
(``ProjectionTerms.identification_checks``): frames of the independent simulator, at case seeds of draws whose
calibration named ``clipping`` (docs/bench/session83.md), and a colour-triple table."""

from __future__ import annotations

import numpy as np
import pytest
import test_independent_sim as sim
from test_tables_and_captures import write_triple_table

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.projection import (
    WHITE_EXCEEDED_MARGIN,
    WHITE_EXCEEDED_SHARE,
    TripleProblem,
)


@pytest.mark.parametrize(
    ("name", "case_seed", "effects", "sensors"),
    [
        # master seed 1428175561 (session 82's matrix): the sensor's well at 0.80 of the ADC, named with the light
        ("projection_clipping", 1810554533, {"additive_light", "albedo_modulation", "clipping"}, True),
        # master seed 4284295412 (session 82's attempt): the ISP's white balance answering the projected cast, no
        # clip planted, named clipping at a white of 0.862
        ("projection_white_balance_unnamed", 4033579101, {"clipping"}, False),
    ],
)
def test_a_clip_is_the_sensors_only_if_its_clean_frames_stay_under_it(
    tmp_path, name, case_seed, effects, sensors
):
    problem, items = sim.drawn_problem(name, case_seed, tmp_path)
    fit = problem.fit(frozenset(effects), items)
    assert fit.params["white"] < 0.95  # both fits do clip below the file's white
    reasons = problem.identification_checks("clipping", fit, items)
    white, share = problem.white_exceeded(fit, items)
    # neither model has a tone curve: the fitted white is in grey levels as it stands
    assert white == pytest.approx(255.0 * fit.params["white"])
    lowest_channel = 255.0 * problem.clean_colours(items).min(dim=1).values
    assert share == float((lowest_channel > white + WHITE_EXCEEDED_MARGIN).double().mean())
    # the check's verdict is the stated rule on the share it reports
    assert (reasons == []) == (share <= WHITE_EXCEEDED_SHARE)
    if sensors:
        assert reasons == []
    else:
        assert len(reasons) == 1 and f"{share:.1%} of the fit items' clean pixels" in reasons[0], reasons
    assert problem.identification_checks("additive_light", fit, items) == []  # the check is the clip's


def test_a_tables_surface_colours_bound_its_clip(tmp_path):
    """A table's surface colours are the clean colours its camera recorded: a white under most of them is not that
    camera's, one over all of them is."""
    rng = np.random.default_rng(3)
    surface = rng.uniform(0.05, 0.9, (200, 3))
    projected = rng.choice([0.0, 127 / 255, 254 / 255], (200, 3))
    problem = TripleProblem(write_triple_table(tmp_path / "t.csv", surface, projected, surface))
    items = np.arange(problem.n_items)
    for white, sensors in ((0.95, True), (0.3, False)):
        fit = Fit(frozenset({"clipping"}), {"opacity": 0.5, "white": white})
        assert (problem.identification_checks("clipping", fit, items) == []) is sensors
