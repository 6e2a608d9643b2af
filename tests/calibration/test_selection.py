"""Forward selection's score (``calibration/core.py``): the pooled RMSE, or the mean of the items' own errors."""

from __future__ import annotations

import typing

import numpy as np
import pytest

from lerobot_phantom.calibration.core import (
    Effect,
    Fit,
    Problem,
    exclusive,
    forward_select,
    item_scores,
    selection_value,
)
from lerobot_phantom.calibration.identify import error_ratio


class LineWithALoneItem(Problem):
    """y = 3 x + noise on every item but one, whose y no fit without it can predict (as a stripe table's only
    sub-threshold condition). The base predicts a constant, ``slope`` a line through 0; both fit by medians, so
    the lone item never moves a fit and its validation error is the same few hundred for both models."""

    candidates = (Effect("slope", "a proportional response"),)

    def __init__(self, score: str, seed: int) -> None:
        rng = np.random.default_rng(seed)
        self.selection_score = score
        self.x = rng.uniform(1.0, 10.0, 24)
        self.y = 3.0 * self.x + rng.normal(0.0, 0.1, 24)
        self.y[5] = 1000.0

    @property
    def n_items(self) -> int:
        return len(self.y)

    def fit(self, effects, items, start=None) -> Fit:
        if "slope" in effects:
            return Fit(effects, {"slope": float(np.median(self.y[items] / self.x[items]))})
        return Fit(effects, {"level": float(np.median(self.y[items]))})

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        predicted = fit.params["slope"] * self.x[items] if "slope" in fit.params else fit.params["level"]
        return float(np.sum((self.y[items] - predicted) ** 2)), len(items)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_one_item_no_model_predicts_decides_the_rmse_but_not_the_mean_item_error(seed):
    items = np.arange(24)
    pooled, steps = forward_select(LineWithALoneItem("rmse", seed), items, seed=seed, margin=0.05)
    assert pooled == frozenset(), steps[0].tried  # the line's gain on 23 items is lost in one item's error
    robust, steps = forward_select(LineWithALoneItem("mean_item_error", seed), items, seed=seed, margin=0.05)
    assert robust == {"slope"}, steps[0].tried
    # the step keeps each item's absolute error, and the identification ratio is a ratio of their means
    before, after = steps[0].item_errors, steps[1].item_errors
    assert before[5] > 900 and after[5] > 900 and np.median(after) < 0.5 < 5 < np.median(before)
    ratio = error_ratio(before, after, draws=100, rng=np.random.default_rng(seed), score="mean_item_error")
    assert ratio.estimate == pytest.approx(before.mean() / after.mean())
    assert ratio.low > 1.0


def test_the_two_scores_from_their_item_terms():
    squared, counts = np.array([4.0, 36.0]), np.array([1.0, 4.0])
    assert selection_value("rmse", item_scores("rmse", squared, counts), counts) == pytest.approx(
        np.sqrt(8.0)
    )
    terms = item_scores("mean_item_error", squared, counts)
    assert terms == pytest.approx([2.0, 3.0])
    assert selection_value("mean_item_error", terms, counts) == pytest.approx(2.5)
    with pytest.raises(ValueError, match="valid: rmse, mean_item_error"):
        item_scores("median", squared, counts)
    with pytest.raises(ValueError, match="valid: rmse, mean_item_error"):
        error_ratio(squared, squared, draws=2, rng=np.random.default_rng(0), score="median")


class FixedErrors(Problem):
    """A problem whose models have no parameters: a model's error is fixed by its effects (``error``) and the same
    on every one of 20 items."""

    @property
    def n_items(self) -> int:
        return 20

    def error(self, effects: frozenset[str]) -> float:
        raise NotImplementedError

    def fit(self, effects, items, start=None) -> Fit:
        return Fit(effects, {})

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        return self.error(fit.effects) ** 2 * len(items), len(items)


class TwoToneCurves(FixedErrors):
    """Two alternative forms of one term (``power`` and ``shoulder``, as sensor_gamma and tone_shoulder) and an
    independent ``glare``. Each helps alone, and the two forms together would fit best of all."""

    candidates = (
        Effect("power", "a power-law tone curve"),
        Effect("shoulder", "a tone curve with a shoulder", excludes=("power",)),
        Effect("glare", "light around the spot"),
    )
    errors: typing.ClassVar[dict[frozenset[str], float]] = {
        frozenset(): 10.0,
        frozenset({"power"}): 5.0,
        frozenset({"shoulder"}): 4.0,
        frozenset({"glare"}): 9.0,
        frozenset({"power", "shoulder"}): 1.0,
        frozenset({"power", "glare"}): 4.5,
        frozenset({"shoulder", "glare"}): 3.5,
        frozenset({"power", "shoulder", "glare"}): 0.5,
    }

    def error(self, effects: frozenset[str]) -> float:
        return self.errors[effects]


def test_exclusive_effects_are_never_tried_together():
    problem = TwoToneCurves()
    assert exclusive(problem.candidates, {"power", "shoulder"})
    assert exclusive(
        problem.candidates, {"shoulder", "power", "glare"}
    )  # symmetric: declared on one side only
    assert not exclusive(problem.candidates, {"power", "glare"})
    chosen, steps = forward_select(problem, np.arange(20), seed=0, margin=0.05)
    assert chosen == {"shoulder", "glare"}, [s.tried for s in steps]
    tried = {name for step in steps for name in step.tried}
    assert not any({"power", "shoulder"} <= set(name.split("+")) for name in tried), tried
    assert all("power" not in step.effects for step in steps)


class MeterToneAndLight(FixedErrors):
    """Three effects each useless alone and in pairs, strong together (as the auto-exposure meter, the tone curve
    and linear light on a filmic camera with auto-exposure); ``tone`` builds on ``light``."""

    candidates = (
        Effect("light", "light adds in linear irradiance"),
        Effect("meter", "auto-exposure"),
        Effect("tone", "a tone curve", requires=("light",)),
    )

    def __init__(self, joint_effects: int) -> None:
        self.joint_effects = joint_effects

    def error(self, effects: frozenset[str]) -> float:
        return {3: 5.0, 2: 9.6}.get(len(effects), 10.0)


def test_a_group_of_three_is_taken_only_when_the_problem_scores_groups_of_three():
    chosen, steps = forward_select(MeterToneAndLight(2), np.arange(20), seed=0, margin=0.05)
    assert chosen == frozenset(), steps[0].tried  # every pair gains 4%, under the margin
    assert not any(name.count("+") == 2 for name in steps[0].tried)
    chosen, steps = forward_select(MeterToneAndLight(3), np.arange(20), seed=0, margin=0.05)
    assert chosen == {"light", "meter", "tone"}, steps[0].tried
    assert steps[0].tried["light+meter+tone"] == pytest.approx(5.0)
    # the two steps inside the group are marked, each a valid model (tone never without light)
    assert [s.paired for s in steps] == [False, True, True, False]
    assert [len(s.effects) for s in steps] == [0, 1, 2, 3]
    assert all("tone" not in s.effects or "light" in s.effects for s in steps)
