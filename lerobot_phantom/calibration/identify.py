"""Identification: bootstrap intervals over items, and the rule that makes an extension a *named cause*.

Every interval here is a percentile bootstrap over *items* (table rows, capture tiles, whole image pairs): items
are drawn with replacement, the statistic is recomputed, and the ``(1 - level) / 2`` and ``(1 + level) / 2``
quantiles of the draws bound it. Items, not values, are resampled because the values inside one item (the pixels
of one frame) are not independent.

The rule (:func:`identify`): an extension is a named cause only if

1. it was selected by the stated criterion on the fit items only (forward selection by inner cross-validation);
2. its effect size on fit data is real: the bootstrap interval of the inner cross-validated error ratio
   (model without it / model with it, paired over the same validation items) lies above 1. An effect that hosts
   others (their parameters live in its form: a stripe model's detection threshold needs the exposure overlap)
   is compared with them: the model without it cannot have them either, so its gain is what it brings together
   with those of its dependants that pass 2-5 on their own (an effect of no use alone is still not named unless
   what it makes possible is); the effects of a group selection took in one step are judged together, so each
   member is compared with what any member of the group hosts, and a member with no parameter of its own (a
   change of form, which rule 4 cannot judge) must also gain over the others, as the step scored them without it
   (:func:`form_gains_in_groups`). And where no other selected effect builds on it, it is not shown redundant once
   every later step is in: the interval of the error ratio of the selected model without it to the selected model, on
   the same folds (``core.forward_select``'s ``Step.without``), does not lie wholly under 1 + half the selection
   margin, or without it another selected effect's own parameter sits at a bound in most folds (:class:`Redundancy`).
   A step never revisits an earlier one, so an effect taken as its step's best can stand in for a form a later step
   brings (camsim's filmic light projection took a sub-white clip while the shoulder's knee ran to its bound, then the
   shoulder, light spread and reflectance, beside which the clip gained nothing: docs/bench/session77.md);
3. none of its own parameters sits at a bound of its search range (a parameter pinned at a bound measures the
   range, not the camera), unless that bound is the form's declared physical limit (``Param.low_limit``: a glare
   whose inner scale lies far inside the clipped core is a pure power law where the frames show it;
   ``Param.high_limit``: a phase drifting over a whole period covers every phase); a value there is reported in the
   result's ``notes`` as at its limit (a bound on the quantity), and the effect is judged by the rest;
4. where the extension reduces to the model without it at a *null value* of a parameter (a halo of amplitude 0,
   a cross-talk matrix with zero off-diagonal terms, a tone curve of exponent 1), the bootstrap interval of at
   least one such parameter excludes its null value; where it has several such parameters whose nulls all sit at a
   bound of their ranges (one drift per recording, each >= 0), it reduces to the model without it only in a draw
   that has every one of them at its null, so the interval of the largest distance from the null among them (a
   share of each range, :func:`joint_null_interval`) excluding 0 suffices: evidence held by few items of each
   parameter leaves each one at its null in some draws, and the extension in none. A parameter no refit moved and
   the fit items do not depend on (:func:`draw_intervals`) excludes nothing: it stays where the search left it, and
   a null elsewhere would look excluded by an interval of zero width;
5. the problem's own adequacy checks of the effect's physics pass, where it has any
   (``problem.identification_checks(effect, fit, items) -> [reasons]``; e.g. a stabiliser's motion blur must be one
   path for the whole frame, so a blur that is not a motion of the image is not named a resonance).

Otherwise it is reported as "not identified" with the reasons, and it is not part of the model that is written.

A cause that an identified effect's form asserts without a term of its own (``Effect.implies``: a shouldered tone
curve is a gamma encoding too) is judged on the written model by rule 4 alone, on its own statistic
(:func:`implied_results`); its effect size is the implying effect's. When the richer of two forms of one term
(``Effect.excludes``) is not identified, the simpler form that selection scored beside it in the same step is
judged in its place (:func:`simpler_form_result`): rule 2 on its own scores, rules 3-4 on the refit.

Selection is greedy, so an extension that fails the rule has still shaped every step after the one that took it.
One that fails on its own evidence (not only because an effect it builds on, or was refitted without, failed) is
withdrawn, and selection and identification run again without it until a pass withdraws nothing; effects that
fail only rule 2's test of the selected model without them are withdrawn one at a time, the one whose removal
costs least first (backward elimination: without it, the others may pay again)
(:func:`select_and_identify`; ``selection.withdrawn`` in report.json). Every pass is
:func:`core.select_forms`: where it took the simpler of two forms of one term, it runs again without that form
(``selection.form_passes``).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from lerobot_phantom.calibration.core import (
    Fit,
    FormPass,
    Problem,
    Step,
    at_bound,
    dependants,
    fit_chain,
    group_label,
    own_params,
    physical_limits,
    requirements,
    score_of_totals,
    select_forms,
    simpler_forms,
)

LEVEL = 0.9  # two-sided coverage of every reported interval
# share of a parameter's range within which an interval end counts as reaching a null on that bound: a thousand
# times the optimiser's start inset (1e-9), far below any estimate; not core.BOUND_TOLERANCE (1e-3), which on a wide
# range swallowed a real end (a read noise of 0.21 us on a 0-1365 us range, session 34)
NULL_AT_BOUND_TOLERANCE = 1e-6
JOINT_NULL_STATISTIC = "largest distance from the null, as a share of each range"
# moves of a parameter, in its search scale (``core.Param.scale``), each way, that must each change the fit items'
# squared error by more than ``UNMEASURED_TOLERANCE`` of it for the parameter to count as measured
UNMEASURED_MOVES = (1e-3, 1.0)
UNMEASURED_TOLERANCE = 1e-9
# draws of the intervals that only re-sum per-item terms (the error ratio of rule 2, the held-out RMSE, the residual
# structure's statistics): a draw costs a weighted sum, not a refit. With 200 draws (until session 44) the 5% end of
# a ratio was Monte Carlo noise that decided rule 2: drawn stripe camera 4111198912 (lit frames), integration offset,
# ratio 1.583, low end over 200 generator streams 1.029 +- 0.033, at or below 1 in 19% of them (the stream the tool
# used was one: offset withdrawn, 341 rows held-out); with 20 000 draws 1.026 +- 0.004 over 40 streams, none at or
# below 1 (docs/bench/session44/ratio_end_streams_4111198912_lit_8864213.txt)
RESUMMED_DRAWS = 20_000
RESUMMED_CHUNK = 4_000_000  # drawn indices per chunk of draws (32 MB), so large item sets stay in memory


@dataclass(frozen=True)
class Interval:
    """A point estimate with its percentile bootstrap interval."""

    estimate: float
    low: float
    high: float
    level: float = LEVEL
    draws: int = 0
    # a parameter's interval: False when no draw moved it and the items do not depend on it (:func:`draw_intervals`):
    # the interval then measures nothing; None for other statistics
    measured: bool | None = None

    def excludes(self, value: float) -> bool:
        return self.measured is not False and (value < self.low or value > self.high)

    def as_dict(self) -> dict:
        values = {
            "estimate": self.estimate,
            "low": self.low,
            "high": self.high,
            "level": self.level,
            "draws": self.draws,
        }
        return values if self.measured is None else {**values, "measured": self.measured}


def percentile_interval(estimate: float, draws: Sequence[float], level: float = LEVEL) -> Interval:
    """``estimate`` with the ``level`` percentile interval of its bootstrap ``draws`` (non-finite draws dropped)."""
    values = np.asarray(draws, dtype=np.float64)
    values = values[np.isfinite(values)]
    if len(values) == 0:
        return Interval(float(estimate), float("nan"), float("nan"), level, 0)
    tail = 100.0 * (1.0 - level) / 2.0
    low, high = np.percentile(values, [tail, 100.0 - tail])
    return Interval(float(estimate), float(low), float(high), level, len(values))


def resample(items: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One bootstrap draw of ``items`` (with replacement, same size, sorted)."""
    items = np.asarray(items)
    return np.sort(rng.choice(items, len(items), replace=True))


def bootstrap(
    statistic: Callable[[np.ndarray], Mapping[str, float]],
    items: np.ndarray,
    *,
    draws: int,
    rng: np.random.Generator,
    level: float = LEVEL,
) -> dict[str, Interval]:
    """Percentile intervals of every value ``statistic(items)`` returns, over ``draws`` item resamples."""
    estimate = dict(statistic(np.asarray(items)))
    samples: dict[str, list[float]] = {k: [] for k in estimate}
    for _ in range(draws):
        values = statistic(resample(items, rng))
        for k in samples:
            samples[k].append(float(values.get(k, np.nan)))
    return {k: percentile_interval(estimate[k], samples[k], level) for k in estimate}


def resummed_totals(columns: np.ndarray, *, draws: int, rng: np.random.Generator) -> np.ndarray:
    """Column totals of ``columns`` (items x k) in ``draws`` item bootstrap resamples: an array (draws, k).

    A resample draws the items with replacement; its totals are each item's count in it times the item's row. The
    draws come from a child of ``rng`` (``Generator.spawn``, which does not advance ``rng``), so the number of draws
    one interval takes never shifts the draws of the refits that follow it. Counting the drawn indices
    (``np.bincount``) and multiplying takes a fifth of ``Generator.multinomial``'s time at 3000 items
    (docs/bench/session44/resummed_draw_cost_8864213.txt)."""
    columns = np.asarray(columns, np.float64)
    n_items = len(columns)
    child = rng.spawn(1)[0]
    totals = np.empty((draws, columns.shape[1]))
    chunk = max(1, RESUMMED_CHUNK // max(n_items, 1))
    for start in range(0, draws, chunk):
        rows = min(chunk, draws - start)
        drawn = child.integers(0, n_items, size=(rows, n_items)) + n_items * np.arange(rows)[:, None]
        counts = np.bincount(drawn.ravel(), minlength=rows * n_items).reshape(rows, n_items)
        totals[start : start + rows] = counts @ columns
    return totals


def error_ratio(
    before: np.ndarray,
    after: np.ndarray,
    *,
    rng: np.random.Generator,
    score: str = "rmse",
    draws: int = RESUMMED_DRAWS,
) -> Interval:
    """score(before) / score(after) with a paired bootstrap over the items; ``score`` as in ``core.SELECTION_SCORES``.

    ``before``, ``after``: per-item terms of the score (``core.item_scores``) of two models on the same items: sums
    of squared errors for "rmse", each item's own error for "mean_item_error". A ratio above 1 means ``after``
    predicts better. Both models score the same items, so value counts cancel: each item counts once."""
    before, after = np.asarray(before, np.float64), np.asarray(after, np.float64)
    n_items = len(before)

    def ratio(before_total, after_total, count_total):
        with_it = score_of_totals(score, after_total, count_total, n_items)
        return score_of_totals(score, before_total, count_total, n_items) / np.maximum(with_it, 1e-300)

    estimate = float(ratio(before.sum(), after.sum(), float(n_items)))
    totals = resummed_totals(np.stack([before, after, np.ones(n_items)], axis=1), draws=draws, rng=rng)
    return percentile_interval(estimate, ratio(totals[:, 0], totals[:, 1], totals[:, 2]))


def rmse_interval(
    squared: np.ndarray, counts: np.ndarray, *, rng: np.random.Generator, draws: int = RESUMMED_DRAWS
) -> Interval:
    """RMSE over items from per-item squared-error sums and value counts, with its item bootstrap interval."""
    squared, counts = np.asarray(squared, np.float64), np.asarray(counts, np.float64)
    estimate = float(score_of_totals("rmse", squared.sum(), counts.sum(), len(squared)))
    totals = resummed_totals(np.stack([squared, counts], axis=1), draws=draws, rng=rng)
    return percentile_interval(estimate, score_of_totals("rmse", totals[:, 0], totals[:, 1], len(squared)))


@dataclass(frozen=True)
class Identification:
    effect: str
    identified: bool
    reasons: tuple[str, ...]
    notes: tuple[str, ...] = ()  # parameters at their physical limit (rule 3): said, but not a reason
    # rule 2's test of the selected model without it is its only reason (select_and_identify withdraws such
    # effects one at a time)
    redundant: bool = False

    def as_dict(self) -> dict:
        return {
            "effect": self.effect,
            "status": "identified" if self.identified else "not identified",
            "identified": self.identified,
            "reasons": list(self.reasons),
            "notes": list(self.notes),
        }


def identify(
    effect: str,
    *,
    selected: bool,
    validation_ratio: Interval | None,
    params: Mapping[str, float],
    bounds: Mapping[str, tuple[float, float]],
    intervals: Mapping[str, Interval],
    nulls: Mapping[str, float],
    limits: Mapping[str, Mapping[str, str]] | None = None,
    joint_null: Interval | None = None,
    redundancy: Redundancy | None = None,
) -> Identification:
    """Apply the module's rule to one extension.

    ``params``/``bounds``: the extension's own fitted parameters and their search ranges; ``intervals``: their
    bootstrap intervals; ``nulls``: the parameter values at which the extension reduces to the model without it
    (empty when it has none: a change of functional form); ``validation_ratio``: the paired bootstrap interval
    of the inner cross-validated error ratio without / with the extension (None if it was never scored);
    ``limits``: parameter -> {bound side: what the model is there}, for bounds that are the form's physical limit
    (``core.physical_limits``: ``Param.low_limit``/``high_limit``); ``joint_null``: the interval of the
    extension's distance from its null when its nulls all sit at bounds (:func:`joint_null_interval`);
    ``redundancy``: the selected model scored without each effect no other builds on (None: not scored)."""
    limits = limits or {}
    reasons = []
    if not selected:
        reasons.append("not selected by the inner cross-validation on the fit items")
    if validation_ratio is None:
        reasons.append("no inner cross-validated effect size")
    elif not validation_ratio.low > 1.0:
        reasons.append(
            f"inner cross-validated error ratio {validation_ratio.estimate:.3f} "
            f"({100 * validation_ratio.level:.0f}% interval {validation_ratio.low:.3f}-{validation_ratio.high:.3f}) "
            "does not exclude 1 (no gain)"
        )
    shown_redundant = redundancy is not None and redundancy.shown(effect)
    if shown_redundant:
        reasons.append(redundancy.reason(effect))
    parameter_reasons, notes = parameter_checks(params, bounds, intervals, nulls, limits, joint_null)
    reasons += parameter_reasons
    held = "" if redundancy is None else redundancy.holds(effect)
    if held:
        notes.append(held)
    return Identification(
        effect, not reasons, tuple(reasons), tuple(notes), redundant=shown_redundant and len(reasons) == 1
    )


@dataclass(frozen=True)
class Redundancy:
    """Rule 2's test of what an effect still brings once every other selected effect is in: per effect no other
    selected effect builds on, the paired bootstrap interval of the inner cross-validated error ratio of the selected
    model without it to the selected model (the last step's ``Step.without``). An effect is shown redundant when the
    whole interval lies under ``1 + margin / 2``: the data then show that it brings less than half the gain
    selection asks of a step, not merely that its gain is uncertain (a reflectance term carried by a few pairs
    gains 7% with an interval reaching under 1; camsim master seed 1396225205). Removal asks for less than entry, as
    stepwise selection's removal threshold sits beside its entry threshold, so that a step and its undoing cannot
    alternate: at the whole margin a planted reflectance that gained 1.1% (0.98-1.04) was withdrawn after the clip
    beside it, and the repeat without both ran the shoulder's knee to its bound and named a power law
    (master seed 913236811; the clips this test withdraws gain -0.9% to +0.3%, interval ends under 0.7%:
    docs/bench/session77.md).

    Nor is an effect shown redundant when, without it, another selected effect's own parameter sits at a bound in
    most fold fits (``pinned_without``, ``core.Step.without_pinned``): the model without it is one selection sets
    aside (``core.pinned_members``), and the effect is what keeps the other identified. camsim projection_crosstalk
    (filmic, master seed 3585595729): without the planted reflectance the shoulder's exponent ran to its bound in 4
    of 4 folds at a ratio of 1.007; the reflectance was withdrawn, and the repeat set every shoulder aside and wrote
    a power law, held-out 3.06 against the planted structure's 2.22 (docs/bench/session101.md)."""

    ratios: Mapping[str, Interval]
    margin: float
    pinned_without: Mapping[str, Mapping[str, str]] = field(default_factory=dict)

    def shown(self, effect: str) -> bool:
        return self.under_bound(effect) and not self.pinned_without.get(effect)

    def under_bound(self, effect: str) -> bool:
        return effect in self.ratios and self.ratios[effect].high < self.bound

    @property
    def bound(self) -> float:
        return 1.0 + self.margin / 2

    def reason(self, effect: str) -> str:
        ratio = self.ratios[effect]
        return (
            f"the selected model without it scores an inner cross-validated error ratio of {ratio.estimate:.4f} "
            f"({100 * ratio.level:.0f}% interval {ratio.low:.4f}-{ratio.high:.4f}) to the selected model, under "
            f"{self.bound:g} (half the selection margin): the effects selected after it hold what it brought"
        )

    def holds(self, effect: str) -> str:
        """Why ``effect``, under the bound, is not shown redundant (empty when it is, or is not under it)."""
        pinned = self.pinned_without.get(effect)
        if not pinned or not self.under_bound(effect):
            return ""
        ratio = self.ratios[effect]
        return (
            f"not shown redundant: the selected model without it scores an error ratio of {ratio.estimate:.4f} "
            f"({ratio.low:.4f}-{ratio.high:.4f}), under {self.bound:g}, but without it "
            + "; ".join(f"{e}: {why}" for e, why in sorted(pinned.items()))
            + " (a model selection sets aside)"
        )


def excludes_null(interval: Interval, null: float, low: float, high: float) -> bool:
    """Whether ``interval`` excludes the ``null`` value of a parameter bounded by [low, high]. A null on a bound
    (a drift of 0, a threshold of 0) is not excluded by an interval end that sits at that same bound: the optimiser
    keeps values a hair inside their bounds (``fit_least_squares`` starts 1e-9 of the range inside), and a draw
    stopped there is a draw at the null, not one beside it (before session 34 a drift interval of 1e-9 to 0.31 on
    the Axis table excluded the null 0 and named ``phase_drift``). "At" is within ``NULL_AT_BOUND_TOLERANCE``."""
    if not interval.excludes(null):
        return False
    side = at_bound(null, low, high, NULL_AT_BOUND_TOLERANCE)
    if side is None:
        return True
    end = interval.low if side == "low" else interval.high
    return at_bound(end, low, high, NULL_AT_BOUND_TOLERANCE) != side


def parameter_checks(
    params: Mapping[str, float],
    bounds: Mapping[str, tuple[float, float]],
    intervals: Mapping[str, Interval],
    nulls: Mapping[str, float],
    limits: Mapping[str, Mapping[str, str]],
    joint_null: Interval | None = None,
) -> tuple[list[str], list[str]]:
    """Rules 3 and 4 on an extension's own parameters: (reasons it fails them, notes of values at their limit).
    ``joint_null``: the interval of :func:`joint_null_interval`, which passes rule 4 when it excludes 0."""
    reasons, notes = [], []
    for name, value in params.items():
        if name in intervals and intervals[name].measured is False:
            notes.append(
                f"{name} = {value:.4g} is not measured: the fit items do not depend on it, and the value is where "
                "the search left it"
            )
            continue
        side = at_bound(value, *bounds[name])
        limit = limits.get(name, {}).get(side, "")
        if limit:
            quantity = "an upper bound" if side == "low" else "a lower bound"
            notes.append(
                f"{name} = {value:.4g} sits at its {side} bound, the form's physical limit: {limit}; the value "
                f"is {quantity}, not a measurement"
            )
        elif side is not None:
            reasons.append(
                f"{name} = {value:.4g} sits at its {side} bound {bounds[name][side == 'high']:.4g}"
            )
    if nulls:
        excluded = [
            n
            for n, null in nulls.items()
            if n in intervals and excludes_null(intervals[n], null, *bounds.get(n, (-np.inf, np.inf)))
        ]
        jointly = joint_null is not None and excludes_null(joint_null, 0.0, 0.0, 1.0)
        if jointly and not excluded:
            notes.append(
                f"no single interval of {', '.join(n for n in nulls if n in intervals)} excludes its null value, "
                f"but together they leave it: {JOINT_NULL_STATISTIC} {joint_null.estimate:.4g} "
                f"[{joint_null.low:.4g}, {joint_null.high:.4g}]"
            )
        if not excluded and not jointly:
            joint_text = (
                ""
                if joint_null is None
                else f", and so does that of the {JOINT_NULL_STATISTIC} ({joint_null.low:.4g}-{joint_null.high:.4g})"
            )
            reasons.append(
                "the interval of "
                + ", ".join(
                    f"{n} ({intervals[n].low:.4g}-{intervals[n].high:.4g})"
                    if intervals[n].measured is not False
                    else f"{n} (not measured)"
                    for n in nulls
                    if n in intervals
                )
                + " includes the null value "
                + ", ".join(f"{n} = {v:g}" for n, v in nulls.items())
                + " at which the extension reduces to the model without it"
                + joint_text
            )
    return reasons, notes


def joint_null_interval(
    nulls: Mapping[str, float],
    bounds: Mapping[str, tuple[float, float]],
    estimate: Mapping[str, float],
    samples: Sequence[Mapping[str, float]],
) -> Interval | None:
    """The interval over bootstrap ``samples`` of an extension's largest distance from its null among its null
    parameters, each as a share of its range (0: the draw is the model without the extension), or None unless it
    has two or more and every null sits at a bound (rule 4; a null inside a range, like a cross-talk leak that may
    be negative, has draws on both sides of it and no draw exactly there, so its distance never reaches 0).
    Measured case: on the Axis table's split 0 the exposure-50 recording's drift rests on two of its fit rows, both
    missing from a draw with chance 0.132 (session 34), and every recording's drift interval reached 0; the draws
    that lock it keep another recording's drift, and withdrawn, the drift left 59.4 rows held-out against 4.96."""
    names = [n for n in nulls if n in estimate and n in bounds]
    on_bounds = all(at_bound(nulls[n], *bounds[n], NULL_AT_BOUND_TOLERANCE) is not None for n in names)
    if len(names) < 2 or not on_bounds:
        return None

    def distance(params: Mapping[str, float]) -> float:
        return max(abs(params[n] - nulls[n]) / (bounds[n][1] - bounds[n][0]) for n in names)

    return percentile_interval(distance(estimate), [distance(s) for s in samples])


# ---------------------------------------------------------------------------------------------------------------
# applying the rule to a forward selection


def parameter_draws(
    problem: Problem, fit: Fit, items: np.ndarray, *, draws: int, rng: np.random.Generator
) -> list[dict[str, float]]:
    """The parameters of ``fit``'s model refitted on ``draws`` resamples of the fit ``items``, each refit started
    from ``fit`` (the estimate); a problem whose fit searches several starting points searches them again (a
    stripe table's row-time regimes), so a draw may leave the estimate's local minimum as the estimator would."""
    return [problem.fit(fit.effects, resample(items, rng), start=fit).params for _ in range(draws)]


def unmeasured_params(
    problem: Problem, fit: Fit, items: np.ndarray, names: Collection[str] | None = None
) -> set[str]:
    """The parameters of ``fit`` (those in ``names``, default all) the ``items`` do not depend on: no move of
    ``UNMEASURED_MOVES`` search scales either way (inside the bounds) changes their squared error by
    ``UNMEASURED_TOLERANCE`` of it. Such a value is wherever the search left it, and every bootstrap refit leaves it
    there: camsim's laser blinding halo case reported the beam width behind a capture's saturated core as 20 [20, 20]
    reference pixels for a capture with no saturated pixel (docs/bench/session81.md)."""
    specs = [p for p in problem.param_specs(fit.effects) if names is None or p.name in names]
    if not specs:
        return set()
    total, _ = problem.squared_errors(fit, items)
    unmeasured = set()
    for spec in specs:
        value = fit.params[spec.name]
        moved = {
            min(max(value + sign * step * spec.scale, spec.low), spec.high)
            for step in UNMEASURED_MOVES
            for sign in (-1.0, 1.0)
        } - {value}
        if all(
            abs(
                problem.squared_errors(Fit(fit.effects, {**fit.params, spec.name: v}, fit.extra), items)[0]
                - total
            )
            <= UNMEASURED_TOLERANCE * total
            for v in moved
        ):
            unmeasured.add(spec.name)
    return unmeasured


def draw_intervals(
    problem: Problem, fit: Fit, items: np.ndarray, samples: Sequence[Mapping[str, float]]
) -> dict[str, Interval]:
    """Percentile intervals of every fitted parameter of ``fit`` over bootstrap refits on resamples of ``items``
    (``parameter_draws``). One that no refit moved and :func:`unmeasured_params` finds the items do not depend on is
    marked as measuring nothing. Both are asked: a prediction flat around the estimate may still be moved by a refit
    (a locked stripe recording's drift moves the predicted rows only past a step), and a problem's refits may leave
    a parameter the items do measure where it was (a value found on a grid)."""
    draws = {k: [float(s.get(k, np.nan)) for s in samples] for k in fit.params}
    unmoved = [k for k, values in draws.items() if values and all(v == fit.params[k] for v in values)]
    unmeasured = unmeasured_params(problem, fit, items, unmoved) if unmoved else set()
    return {
        k: replace(percentile_interval(fit.params[k], values), measured=k not in unmeasured)
        for k, values in draws.items()
    }


def measured_nulls(nulls: Mapping[str, float], intervals: Mapping[str, Interval]) -> dict[str, float]:
    """The ``nulls`` of parameters whose ``intervals`` measure them (rule 4's joint test reads only those)."""
    return {k: v for k, v in nulls.items() if intervals[k].measured is not False}


def parameter_intervals(
    problem: Problem, fit: Fit, items: np.ndarray, *, draws: int, rng: np.random.Generator
) -> dict[str, Interval]:
    """Percentile intervals of every fitted parameter over ``draws`` bootstrap refits (``parameter_draws``)."""
    return draw_intervals(problem, fit, items, parameter_draws(problem, fit, items, draws=draws, rng=rng))


def implied_results(
    problem: Problem, results: Sequence[dict], fit: Fit, samples: Sequence[Mapping[str, float]]
) -> list[dict]:
    """The causes that the written model's identified effects imply (``Effect.implies``) without a term of their
    own. Each is judged by its statistic on ``fit`` (``Problem.implied_statistic``), whose interval over the same
    bootstrap refits as the parameters' (``samples``) must exclude its null value (rule 4); its effect size is the
    implying effect's, which passed rule 2."""
    implies = {e.name: e.implies for e in problem.candidates}
    for effect, names in implies.items():
        for implied in names:
            if implied not in implies:  # a named cause needs its cause text, which candidates carry
                raise ValueError(
                    f"{effect} implies {implied}, not a candidate of {type(problem).__name__}; "
                    f"valid: {', '.join(implies)}"
                )
    judged = {r["effect"] for r in results}
    out = []
    for result in results:
        effect = result["effect"]
        if not result["identified"] or effect not in fit.effects:
            continue
        for implied in implies.get(effect, ()):
            if implied in fit.effects or implied in judged:
                continue
            judged.add(implied)
            name, value, null = problem.implied_statistic(effect, implied, fit.params)
            interval = percentile_interval(
                value, [problem.implied_statistic(effect, implied, s)[1] for s in samples]
            )
            reasons = []
            if not interval.excludes(null):
                reasons.append(
                    f"the interval of {name} ({interval.low:.4g}-{interval.high:.4g}) includes the null value "
                    f"{name} = {null:g}, at which {effect}'s fitted form shows no {implied}"
                )
            out.append(
                {
                    **Identification(
                        implied,
                        not reasons,
                        tuple(reasons),
                        (
                            f"implied by {effect}: the written model holds that form, which asserts this cause too",
                        ),
                    ).as_dict(),
                    "implied_by": effect,
                    "validation_ratio": result["validation_ratio"],
                    "compared_steps": result["compared_steps"],
                    "judged_with": result["judged_with"],
                    "params": {name: value},
                    "intervals": {name: interval.as_dict()},
                    "nulls": {name: null},
                }
            )
    return out


@dataclass
class Selection:
    """What identification leaves of a forward selection."""

    selected: list[str]
    identified: list[str]
    results: list[dict]
    fit: Fit  # the model with the identified effects only, fitted on the fit items
    intervals: dict[str, Interval]  # its parameters' intervals
    # selected effects that failed the rule on their own evidence, not only because an effect they build on or
    # were refitted without failed (select_and_identify withdraws them); of those that fail only the test of the
    # selected model without them (rule 2), the one whose removal costs least, and only when no other fails
    rejected: list[str] = field(default_factory=list)
    # the selection passes repeated without a simpler form of a term (core.select_forms), set by select_and_identify
    form_passes: list[FormPass] = field(default_factory=list)
    # candidates never tried, with the reason (Problem.unoffered on the fit items), set by select_and_identify
    unoffered: dict[str, str] = field(default_factory=dict)


def identify_selection(
    problem: Problem,
    steps: list[Step],
    chain: list[Fit],
    fit_items: np.ndarray,
    *,
    draws: int,
    rng: np.random.Generator,
    redundancy: Redundancy | None = None,
    group_gains: Mapping[str, GroupGain] | None = None,
) -> Selection:
    """Judge every extension forward selection kept by the module's rule; refit without those that fail.
    ``redundancy``: :func:`redundancy` of the steps (None: rule 2's test of the selected model without each effect is
    not made); ``group_gains``: :func:`form_gains_in_groups` of the steps (None: not made)."""
    selected_fit = chain[-1]
    samples = parameter_draws(problem, selected_fit, fit_items, draws=draws, rng=rng)
    intervals = draw_intervals(problem, selected_fit, fit_items, samples)
    entries = selection_entries(steps)
    own = own_evidence_results(
        problem,
        steps,
        entries,
        selected_fit,
        intervals,
        fit_items,
        samples=samples,
        rng=rng,
        redundancy=redundancy,
        group_gains=group_gains,
    )
    # taken before the passes below add collateral reasons (an effect it builds on, or a refit without one, failed)
    rejected = sorted(
        effect for effect, result in own.items() if not result["identified"] and not result["redundant"]
    )
    redundant = [effect for effect, result in own.items() if result["redundant"]]
    if redundant and not rejected:
        # one at a time, as backward elimination: without the one the others hold best, the rest may gain again
        rejected = [min(redundant, key=lambda e: own[e]["ratio_without"]["estimate"])]
    results, identified = requirement_results(problem, entries, own)
    for effect, before, after in entries:
        if not own[effect]["identified"]:
            fallback = simpler_form_result(problem, steps, effect, before, after, identified, rng=rng)
            if fallback is not None:
                results.append(fallback)
                if fallback["identified"]:
                    identified.append(fallback["effect"])
    final, final_intervals, final_samples = selected_fit, intervals, samples
    if frozenset(identified) != selected_fit.effects:
        final, final_intervals, final_samples = refit_identified(
            problem, chain, results, frozenset(identified), fit_items, draws=draws, rng=rng
        )
    results += implied_results(problem, results, final, final_samples)
    return Selection(
        sorted(selected_fit.effects), sorted(final.effects), results, final, final_intervals, rejected
    )


def selection_entries(steps: list[Step]) -> list[tuple[str, int, int]]:
    """(effect, index of the step before it, index of the step with it) in the order selection added them; the
    effects of a group taken in one step (interacting, each useless alone) are judged by what they bring together,
    from the step before the group to the step after it."""
    entries = []
    for k, (before, after) in enumerate(itertools.pairwise(steps)):
        (effect,) = set(after.effects) - set(before.effects)
        first, last = k, k + 1
        while steps[first].paired:
            first -= 1
        while steps[last].paired:
            last += 1
        entries.append((effect, first, last))
    return entries


def redundancy(problem: Problem, steps: list[Step], *, margin: float, rng: np.random.Generator) -> Redundancy:
    """The :class:`Redundancy` test of the effects the selection's last step scored the selected model without
    (``Step.without``), at the selection's ``margin``."""
    last = steps[-1]
    ratios = {
        effect: error_ratio(terms, last.item_errors, rng=rng, score=problem.selection_score)
        for effect, terms in sorted(last.without_item_errors.items())
    }
    return Redundancy(ratios, margin, last.without_pinned)


@dataclass(frozen=True)
class GroupGain:
    """What a change of form taken in one step with other effects brings beside them (:func:`form_gains_in_groups`):
    the step's scored group of the others, and the paired bootstrap interval of its inner cross-validated error
    ratio to the whole group."""

    others: str  # the group of the others, by its label in the step's ``tried``
    ratio: Interval

    def reason(self) -> str:
        ratio = self.ratio
        return (
            f"a change of form taken in one step with {self.others}, with no parameter of its own to show a null "
            f"excluded: those alone score an inner cross-validated error ratio of {ratio.estimate:.3f} "
            f"({100 * ratio.level:.0f}% interval {ratio.low:.3f}-{ratio.high:.3f}) to the group with it, which does "
            "not exclude 1 (no gain of its own)"
        )


def form_gains_in_groups(
    problem: Problem, steps: list[Step], *, rng: np.random.Generator
) -> dict[str, GroupGain]:
    """Per effect with no parameter of its own that a selection step took in a group with others, where the step
    scored (and did not set aside) the group of the others without it and without what builds on it: its
    :class:`GroupGain`. A group is judged by what its members bring together (rule 2), and a member with a
    parameter shows its own part by rule 4; a change of form has no parameter, so the group's gain would name it
    on the others' evidence. Rule 2 asks this of it, as of an effect taken in a step of its own: the second
    camera's placement table of STRIPES_SEED=2369029544 took the drift's start at the stripes' entry with the
    exposure overlap and the drift in one step, 6.54 rows against the pair's 6.93 (ratio 1.060, 0.902-1.287), and
    the entry start ran a recording's drift to a whole period (held-out 30.51 rows, the pair's 23.31:
    docs/bench/session100.md)."""
    requires = requirements(problem)
    gains = {}
    for effect, before, after in selection_entries(steps):
        chosen = frozenset(steps[before].effects)
        model = frozenset(steps[after].effects)
        group = model - chosen
        if len(group) < 2 or own_params(problem, model, effect):
            continue
        others = group - {effect} - dependants(problem, model, effect)
        label = "+".join(group_label(others, chosen, requires))
        if not others or label not in steps[before].tried_item_errors or label in steps[before].set_aside:
            continue
        ratio = error_ratio(
            steps[before].tried_item_errors[label],
            steps[after].item_errors,
            rng=rng,
            score=problem.selection_score,
        )
        gains[effect] = GroupGain(label, ratio)
    return gains


def own_evidence_results(
    problem: Problem,
    steps: list[Step],
    entries: list[tuple[str, int, int]],
    selected_fit: Fit,
    intervals: Mapping[str, Interval],
    fit_items: np.ndarray,
    *,
    samples: Sequence[Mapping[str, float]],
    rng: np.random.Generator,
    redundancy: Redundancy | None,
    group_gains: Mapping[str, GroupGain] | None = None,
) -> dict[str, dict]:
    """Each selected effect's result by the rule on its own evidence: its validation ratio, the ratio of the
    selected model without it (``redundancy``; ``redundant`` when that alone fails), what a change of form taken in
    a group brings beside the others (``group_gains``) and its own parameters in the selected model (``samples``:
    the bootstrap refits ``intervals`` come from). Leaves first: an effect that hosts others (the form their
    parameters live in) is judged with those of them that pass on their own, because the model without it cannot
    have them either; so is every other member of a group taken with it in one step."""
    own: dict[str, dict] = {}
    for effect, before, after in reversed(entries):
        hosted = {d for d in dependants(problem, selected_fit.effects, effect) if own[d]["identified"]}
        # a group taken in one step is judged by what its members bring together, so what one member hosts is the
        # group's gain for every member: a drawn stripe camera (4111198912, lit frames) took a threshold with an
        # integration offset (ratio 1.22 over the step before the pair), then read noise on the threshold (2.40);
        # without the offset, threshold and noise score 8.23 against 4.09 rows, the noise pinned at 0. Judged to
        # the pair's step only, the offset was withdrawn: 341 rows held-out, against 2.80 with it.
        group = {e for e, b, a in entries if (b, a) == (before, after)}
        carried = hosted | {
            d
            for member in group - {effect}
            for d in dependants(problem, selected_fit.effects, member)
            if d not in group and own[d]["identified"]
        }
        if carried:
            after = max(after, next(i for i, s in enumerate(steps) if set(s.effects) >= carried | {effect}))
        ratio = None
        if steps[before].item_errors is not None and steps[after].item_errors is not None:
            ratio = error_ratio(
                steps[before].item_errors, steps[after].item_errors, rng=rng, score=problem.selection_score
            )
        specs = own_params(problem, selected_fit.effects, effect)
        params = {p.name: selected_fit.params[p.name] for p in specs}
        nulls = {k: v for k, v in problem.null_values(effect).items() if k in selected_fit.params}
        bounds = {p.name: (p.low, p.high) for p in specs}
        joint_null = joint_null_interval(
            measured_nulls(nulls, intervals), bounds, selected_fit.params, samples
        )
        outcome = identify(
            effect,
            selected=True,
            validation_ratio=ratio,
            params=params,
            bounds=bounds,
            intervals={p.name: intervals[p.name] for p in specs},
            nulls=nulls,
            limits=physical_limits(specs),
            joint_null=joint_null,
            redundancy=redundancy,
        )
        result = outcome.as_dict()
        without = None if redundancy is None else redundancy.ratios.get(effect)
        result["redundant"] = outcome.redundant
        failed = []
        group_gain = (group_gains or {}).get(effect)
        if group_gain is not None:
            result["gain_in_group"] = {"others": group_gain.others, **group_gain.ratio.as_dict()}
            if not group_gain.ratio.low > 1.0:
                failed.append(group_gain.reason())
        # problem-specific adequacy checks of the effect's physics (e.g. a blur path must be one path for the
        # whole frame); each failed check is a reason
        checks = getattr(problem, "identification_checks", None)
        if checks is not None and outcome.identified:
            failed += checks(effect, selected_fit, fit_items)
        if failed:
            result.update(identified=False, status="not identified", redundant=False)
            result["reasons"].extend(failed)
        result.update(
            validation_ratio=None if ratio is None else ratio.as_dict(),
            # the selection steps the ratio compares (an interacting pair: from the step before the pair)
            compared_steps=[before, after],
            judged_with=sorted(hosted),
            ratio_without=None if without is None else without.as_dict(),
            params=params,
            intervals={p.name: intervals[p.name].as_dict() for p in specs},
            nulls=nulls,
        )
        if joint_null is not None:
            result["joint_null"] = {"statistic": JOINT_NULL_STATISTIC, **joint_null.as_dict()}
        own[effect] = result
    return own


def requirement_results(
    problem: Problem, entries: list[tuple[str, int, int]], own: dict[str, dict]
) -> tuple[list[dict], list[str]]:
    """The results in selection order, an effect that builds on one not identified failing with it, and the
    identified effects."""
    results, identified = [], []
    for effect, _before, _after in entries:
        result = own[effect]
        requires = next((e.requires for e in problem.candidates if e.name == effect), ())
        missing = [r for r in requires if r not in identified]
        if missing and result["identified"]:
            result.update(identified=False, status="not identified")
            result["reasons"].append(f"builds on {', '.join(missing)}, which is not identified")
        results.append(result)
        if result["identified"]:
            identified.append(effect)
    return results, identified


def refit_identified(
    problem: Problem,
    chain: list[Fit],
    results: list[dict],
    kept: frozenset[str],
    fit_items: np.ndarray,
    *,
    draws: int,
    rng: np.random.Generator,
) -> tuple[Fit, dict[str, Interval], list[dict[str, float]]]:
    """The model with the identified effects only, refitted on the fit items, with its parameters' intervals and
    draws. Its own parameters are held to rules 3 and 4 too: without a dropped effect, one that passed may fall to
    its null (a meter that only balanced a glare, refitted without the glare). An effect that fails, and those that
    build on it, are marked in ``results`` and dropped, and the rest refitted until none fails."""
    selected_effects = chain[-1].effects
    by_effect = {r["effect"]: r for r in results}
    while True:
        # the largest model of the chain inside the kept set starts the refit
        start = max((f for f in chain if f.effects <= kept), key=lambda f: len(f.effects))
        final = start if start.effects == kept else problem.fit(kept, fit_items, start)
        final_samples = parameter_draws(problem, final, fit_items, draws=draws, rng=rng)
        final_intervals = draw_intervals(problem, final, fit_items, final_samples)
        failing = {
            effect: reasons
            for effect in sorted(kept)
            if (
                reasons := refit_reasons(
                    problem, final, final_intervals, effect, selected_effects - kept, final_samples
                )
            )
        }
        if not failing:
            for result in results:
                if result.get("in_place_of") and result["identified"]:
                    specs = own_params(problem, final.effects, result["effect"])
                    result["params"] = {p.name: final.params[p.name] for p in specs}
                    result["intervals"] = {p.name: final_intervals[p.name].as_dict() for p in specs}
            return final, final_intervals, final_samples
        for effect, reasons in failing.items():
            by_effect[effect].update(identified=False, status="not identified")
            by_effect[effect]["reasons"].extend(reasons)
        dropped = set(failing).union(*(dependants(problem, kept, e) for e in failing))
        for effect in dropped - set(failing):
            by_effect[effect].update(identified=False, status="not identified")
            by_effect[effect]["reasons"].append(
                f"builds on {', '.join(sorted(failing))}, which is not identified"
            )
        kept = kept - dropped


def simpler_form_result(
    problem: Problem,
    steps: list[Step],
    effect: str,
    before: int,
    after: int,
    identified: Sequence[str],
    *,
    rng: np.random.Generator,
) -> dict | None:
    """The simpler form of a term whose richer form ``effect`` is not identified, judged in its place, or None.

    Selection scored both forms of the term in the same step and took the richer one by the margin
    (``core.forward_select``); when the richer one then fails the rule (a knee exponent pinned at its bound, on a
    camera whose curve is a power law), the model it leaves has no form of the term at all. The simpler form
    takes its place if that step scored it as eligible with the same other effects, all of them identified, and
    its gain over the model before the step passes rule 2; the refit that follows holds it to rules 3 and 4. The
    result says whose place it took (``in_place_of``) and the score it was selected by (``scored``)."""
    chosen = frozenset(steps[before].effects)
    group = frozenset(steps[after].effects) - chosen
    requires = requirements(problem)
    if steps[before].item_errors is None:
        return None
    for alternative in simpler_forms(problem, chosen | group, effect):
        label = "+".join(group_label((group - {effect}) | {alternative}, chosen, requires))
        eligible = label in steps[before].tried_item_errors and label not in steps[before].set_aside
        if eligible and (group - {effect}) | requires[alternative] <= set(identified):
            break
    else:
        return None
    terms = steps[before].tried_item_errors[label]
    ratio = error_ratio(steps[before].item_errors, terms, rng=rng, score=problem.selection_score)
    outcome = identify(
        alternative,
        selected=True,
        validation_ratio=ratio,
        params={},
        bounds={},
        intervals={},
        nulls={},
    )
    return {
        **outcome.as_dict(),
        "in_place_of": effect,
        "scored": {"group": label, "validation_error": steps[before].tried[label]},
        "validation_ratio": ratio.as_dict(),
        "compared_steps": [before, after],
        "judged_with": [],
        "params": {},
        "intervals": {},
        "nulls": dict(problem.null_values(alternative)),
    }


def refit_reasons(
    problem: Problem,
    fit: Fit,
    intervals: Mapping[str, Interval],
    effect: str,
    dropped: frozenset[str],
    samples: Sequence[Mapping[str, float]],
) -> list[str]:
    """Why ``effect``'s own parameters in ``fit`` (the refit without ``dropped``, ``samples`` its bootstrap refits)
    fail rules 3 or 4, if they do."""
    specs = own_params(problem, fit.effects, effect)
    bounds = {p.name: (p.low, p.high) for p in specs}
    nulls = {k: v for k, v in problem.null_values(effect).items() if k in fit.params}
    reasons, _ = parameter_checks(
        {p.name: fit.params[p.name] for p in specs},
        bounds,
        intervals,
        nulls,
        physical_limits(specs),
        joint_null_interval(measured_nulls(nulls, intervals), bounds, fit.params, samples),
    )
    return [f"refitted without {', '.join(sorted(dropped))}, {reason}" for reason in reasons]


@dataclass
class Withdrawal:
    """An effect a selection pass took and identification rejected on its own evidence."""

    effect: str
    selection_pass: int
    reasons: list[str]
    # the steps of the pass that took it (report.json ``selection.earlier_passes``): the last pass's steps alone do
    # not show what was tried with it, nor why its pass chose it
    pass_steps: list[Step] = field(repr=False, compare=False)

    def as_dict(self) -> dict:
        return {"effect": self.effect, "pass": self.selection_pass, "reasons": list(self.reasons)}


def select_and_identify(
    problem: Problem,
    fit_items: np.ndarray,
    *,
    seed: int,
    margin: float,
    folds: int,
    draws: int,
) -> tuple[list[Step], list[Fit], Selection, list[Withdrawal]]:
    """Forward selection and identification, repeated without the effects identification rejects on their own
    evidence (the module docstring says why) until a pass rejects none (where all a pass rejects fail only the
    test of the selected model without them, the one whose removal costs least, as backward elimination, since
    without it the others may pay again): (steps, chain, selection) of the last pass
    and what was withdrawn (each withdrawal holds its pass's steps). Each pass sees the fit items only and has the
    same seeds, so a pass that withdraws nothing is the single pass of before. Measured case: camsim's blinding
    auto-exposure (master seed 3986568970), where a power law at its bound 4 beat the meter with linear light by
    0.6% at the first step."""
    withdrawn: list[Withdrawal] = []
    unoffered = problem.unoffered(fit_items)
    while True:
        _selected, steps, form_passes = select_forms(
            problem,
            fit_items,
            seed=seed,
            margin=margin,
            folds=folds,
            withdrawn=frozenset(unoffered) | frozenset(w.effect for w in withdrawn),
        )
        chain = fit_chain(problem, steps, fit_items)
        selection = identify_selection(
            problem,
            steps,
            chain,
            fit_items,
            draws=draws,
            rng=np.random.default_rng([seed, 1]),
            # a stream of their own: the intervals of before are drawn as they were
            redundancy=redundancy(problem, steps, margin=margin, rng=np.random.default_rng([seed, 6])),
            group_gains=form_gains_in_groups(problem, steps, rng=np.random.default_rng([seed, 7])),
        )
        selection.form_passes = form_passes
        selection.unoffered = unoffered
        if not selection.rejected:
            return steps, chain, selection, withdrawn
        number = 1 + max((w.selection_pass for w in withdrawn), default=0)
        reasons = {r["effect"]: r["reasons"] for r in selection.results if r["effect"] in selection.rejected}
        withdrawn += [
            Withdrawal(effect, number, list(reasons[effect]), steps) for effect in selection.rejected
        ]
