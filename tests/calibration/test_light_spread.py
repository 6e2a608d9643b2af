"""Light projection frame pairs: light that spreads across the projected pattern's edges is found, measured and
named only when it is there (``projection.LIGHT_SPREAD``)."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from calibration_testkit import assert_kept_values_change_no_prediction, projection_pairs_with_spread_light

from lerobot_phantom.calibration.frame_models.light_projection import (
    LIGHT_MEMO_SIZE,
    ProjectionFrames,
    projected_light_params,
)
from lerobot_phantom.calibration.identify import select_and_identify
from lerobot_phantom.calibration.projection import TripleProblem
from lerobot_phantom.transforms.light_projection import LightProjection


@pytest.mark.slow
@pytest.mark.sampled
@pytest.mark.parametrize("spread_px", [0.0, 1.0])
def test_light_spread_is_named_and_measured_only_when_the_light_spreads(spread_px):
    # scipy's Gaussian blur of the sharp frame the projector was sent (calibration_testkit), not the package's
    pairs = projection_pairs_with_spread_light(spread_px, seed=3)
    problem = ProjectionFrames(pairs, seed=3, pattern_record="captured")
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


@pytest.mark.parametrize("record", ["captured", "emitted"])
def test_kept_light_changes_no_prediction_along_a_finite_difference_jacobian(record):
    """The decoded and spread light a fit reuses between the columns of a finite-difference Jacobian
    (``ProjectionFrames.memoised_light``) must equal the light computed afresh for every parameter step, including
    steps of the tone curve, of the spread and, for a captured pattern, of the colour correction (which takes it to
    the raw channels, ``physics.captured_light_to_raw``), which change it; an emitted pattern is not spread again
    for a step of the matrix."""
    pairs = projection_pairs_with_spread_light(1.0, seed=5)
    effects = frozenset(
        {
            "additive_light",
            "channel_crosstalk",
            "tone_shoulder",
            "sensor_gamma",
            "light_spread",
            "colour_correction",
        }
    )
    kept, fresh = (
        ProjectionFrames(pairs, seed=5, pattern_record=record),
        ProjectionFrames(pairs, seed=5, pattern_record=record),
    )
    # the features of all pairs stacked, as a fit stacks them
    per_pair = [kept.features(i, kept.samples[i]) for i in range(len(pairs))]
    feats = {k: torch.cat([f[k] for f in per_pair]) for k in per_pair[0]}
    spreads = []
    spread_light = kept.spread_light
    kept.spread_light = lambda *args: spreads.append(args) or spread_light(*args)
    steps = assert_kept_values_change_no_prediction(kept, fresh, "light_memo", effects, feats)
    # the light was spread anew only for the steps that move the light's own parameters (and the first point),
    # and the memo stays bounded while the steps run through every parameter
    light_params = projected_light_params(steps[0], spread=True)
    assert ("ccm_red" in light_params) == (record == "captured")
    moving = sum(name in light_params for name in steps[0])
    assert len(spreads) == 1 + moving < len(steps)
    assert len(kept.light_memo) <= LIGHT_MEMO_SIZE


def test_a_jacobian_taken_by_torch_passes_the_kept_light_by():
    """Under a torch Jacobian (``fit_least_squares(jacobian="reverse")``) the kept light is neither read nor keyed:
    the derivative in a tone parameter and in the spread matches a central difference."""
    pairs = projection_pairs_with_spread_light(1.0, seed=5)
    effects = frozenset({"additive_light", "sensor_gamma", "light_spread"})
    problem = ProjectionFrames(pairs, seed=5, pattern_record="captured")
    feats = problem.features(0, problem.samples[0])
    names = ("gamma", "spread_ref_px")
    point = {spec.name: spec.init for spec in problem.param_specs(effects)}

    def predicted(values: torch.Tensor) -> torch.Tensor:
        params = {k: torch.tensor(v, dtype=torch.float64) for k, v in point.items()}
        params.update(dict(zip(names, values, strict=True)))
        return problem.predict_features(effects, params, feats).sum()

    at = torch.tensor([point[n] for n in names], dtype=torch.float64)
    with torch.no_grad():  # a value computed without autograd is kept at this very point first
        predicted(at)
    jacobian = torch.func.jacrev(predicted)(at)
    step = 1e-6
    with torch.no_grad():
        central = torch.stack(
            [
                (predicted(at + step * e) - predicted(at - step * e)) / (2 * step)
                for e in torch.eye(2, dtype=at.dtype)
            ]
        )
    torch.testing.assert_close(jacobian, central, rtol=1e-4, atol=1e-6)
