"""Light projection frame pairs: light that spreads across the projected pattern's edges is found, measured and
named only when it is there (``projection.LIGHT_SPREAD``)."""

from __future__ import annotations

import numpy as np
import pytest
from calibration_testkit import projection_pairs_with_spread_light

from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.identify import select_and_identify
from lerobot_phantom.calibration.projection import TripleProblem
from lerobot_phantom.transforms.light_projection import LightProjection


@pytest.mark.slow
@pytest.mark.parametrize("spread_px", [0.0, 1.0])
def test_light_spread_is_named_and_measured_only_when_the_light_spreads(spread_px):
    # scipy's Gaussian blur of the sharp frame the projector was sent (calibration_testkit), not the package's
    pairs = projection_pairs_with_spread_light(spread_px, seed=3)
    problem = ProjectionFrames(pairs, seed=3)
    _, chain, selection, _ = select_and_identify(
        problem, np.arange(len(pairs)), seed=3, margin=0.05, folds=3, draws=60
    )
    if spread_px == 0.0:
        assert "light_spread" not in selection.selected, selection.selected
        return
    assert "light_spread" in selection.identified, (selection.selected, selection.identified)
    # a pixel of spread at 50 px wide is 256 / 50 pixels at the 256-pixel reference
    assert chain[-1].params["spread_ref_px"] == pytest.approx(spread_px * 256 / 50, rel=0.05)
    # calibrated.json hands the fitted spread to the attack, which takes it
    kwargs = problem.transform_kwargs(chain[-1])
    assert kwargs["spread"] == chain[-1].params["spread_ref_px"]
    assert LightProjection(**kwargs).physical["spread"] == kwargs["spread"]


def test_colour_triple_tables_are_not_offered_light_spread():
    # a table row has no neighbouring pixels for light to spread to
    assert "light_spread" not in {e.name for e in TripleProblem.candidates}
    assert "light_spread" in {e.name for e in ProjectionFrames.candidates}
