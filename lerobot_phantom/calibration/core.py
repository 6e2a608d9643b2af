"""The model-agnostic part of calibration: parametric models, least-squares fits, seeded splits, selection.

A *problem* is one kind of measured data with a base model (the paper's simulation) and a library of named
physical extensions. Its data is cut into *items* (table rows, image tiles or whole images) so that splits never
share an item between fitting and scoring. Selection is forward: starting from the base, the extension that most
lowers the inner cross-validated error is kept if it lowers it by a clear relative margin, or a pair of extensions
when the pair beats every single one by that margin (interacting effects); repeat until nothing does. Where a
pass took the simpler of two forms of one term, it is repeated without that form (:func:`select_forms`). The error is
the problem's ``selection_score``: the RMSE over all values, or the mean of the items' own errors where one item that
no fit can predict would otherwise decide every comparison.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import torch
from scipy.optimize import least_squares
from threadpoolctl import threadpool_limits


@contextmanager
def single_threaded() -> Iterator[None]:
    """Run fits on one thread: the many small dense products of least squares slow down badly when BLAS and
    torch spread them over cores that other processes also use (measured: 6x on a loaded 2-core machine), and a fit
    ends where its reductions' order leads it, which the thread count sets (a camsim projection draw's gamma 1.914 on
    one thread, 1.959 on two: docs/bench/session101/structures_threads_e38c879.txt)."""
    torch_threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        with threadpool_limits(limits=1):
            yield
    finally:
        torch.set_num_threads(torch_threads)


@dataclass(frozen=True)
class Effect:
    """A named physical extension: its cause in plain words, the effects it builds on and the effects it is an
    alternative to (``excludes``: two forms of one physical term, never in one model; the relation is symmetric).

    ``implies``: causes this effect's form asserts too, without their own term in the model (a shouldered tone
    curve is also a gamma encoding of linear light). Each is judged on the written model by its own statistic
    (``Problem.implied_statistic``), with the same interval rule as a parameter's null value (identify.py)."""

    name: str
    cause: str
    requires: tuple[str, ...] = ()
    excludes: tuple[str, ...] = ()
    implies: tuple[str, ...] = ()


def exclusive(candidates: tuple[Effect, ...], effects: frozenset[str] | set[str]) -> bool:
    """Whether ``effects`` holds two effects one of which ``excludes`` the other."""
    return any(set(e.excludes) & set(effects) for e in candidates if e.name in effects)


BOUND_TOLERANCE = 1e-3  # share of a parameter's range within which it counts as sitting at the bound
TIE_SHARE = 1e-6  # errors or scores that agree within this share are equal (preferred_fit, lowest_scoring)


def ties_lowest(value: float | np.ndarray, lowest: float) -> bool | np.ndarray:
    """Whether ``value`` ties with ``lowest``, the least of its kind: within ``TIE_SHARE`` of it, where the data do
    not tell the two apart (elementwise for an array of values)."""
    return value <= lowest + abs(lowest) * TIE_SHARE


@dataclass(frozen=True)
class Param:
    """A fitted parameter: start value, bounds and a typical magnitude (the optimiser works in ``value/scale``).

    ``low_limit``, when given, says what the model *is* at the low bound: a bound where the form converges to a
    physical limit the frames cannot tell from it (a glare's inner scale far inside the clipped core: a pure power
    law), rather than an edge of the search. A value there is reported as "at its limit" (an upper bound on the
    quantity), not as a parameter pinned at a bound (identify.py, rule 3). ``high_limit`` says the same of the
    high bound (a phase that drifts over a whole period covers every phase: drifting further changes nothing)."""

    name: str
    init: float
    low: float
    high: float
    scale: float = 1.0
    low_limit: str = ""
    high_limit: str = ""

    def limit(self, side: str) -> str:
        """What the model is at bound ``side`` ("low"/"high") when that bound is a physical limit, else ""."""
        return self.low_limit if side == "low" else self.high_limit


def physical_limits(specs: Sequence[Param]) -> dict[str, dict[str, str]]:
    """Parameter -> {bound side: what the model is there} for the bounds declared physical limits."""
    return {
        p.name: {side: p.limit(side) for side in ("low", "high") if p.limit(side)}
        for p in specs
        if p.low_limit or p.high_limit
    }


@dataclass
class Fit:
    effects: frozenset[str]
    params: dict[str, float]
    extra: dict = field(default_factory=dict)  # per-item nuisance values etc.


def further_starts(start: Fit | None, effects: frozenset[str]) -> list[dict[str, float]]:
    """Starts of a warm-started fit beside the warm one (``fit_least_squares(starts=...)``).

    A model extending a nested fit also starts from the defaults: a warm start from a nested model's optimum can
    stall (a saturated spot's fit at the blend's values). A refit of the same model on resampled items (the
    bootstrap of identify.py) starts from its own estimate only: the defaults would double its cost and, when
    they win, measure the optimiser's other basin rather than the items' variation."""
    return [{}] if start is not None and start.effects != effects and start.params else []


# how fit_least_squares takes a Jacobian: scipy's forward finite differences ("2-point", one residual evaluation
# per parameter), torch forward mode under vmap ("forward") or reverse mode under vmap ("reverse", one backward pass
# per residual, batched). Finite differences are the default: forward mode runs each elementwise op that mixes a
# parameter with a plain tensor or number as a Python decomposition (torch 2.10), which cost more than the n
# evaluations on every shared input, with the same fits (docs/bench/jacobian_choice.py). Stripe fits need exact
# derivatives (stripes.STRIPE_JACOBIAN: a regression draw where finite differences stop in another minimum) and
# take reverse mode, which has no such decomposition: the same Jacobian to 1e-12 in 1/16 of forward mode's time
JACOBIANS = ("2-point", "forward", "reverse")
JACOBIAN = "2-point"


def fit_least_squares(
    params: Sequence[Param],
    residuals: Callable[[dict[str, torch.Tensor]], torch.Tensor],
    *,
    max_nfev: int = 200,
    starts: Sequence[dict[str, float]] = (),
    jacobian: str | None = None,
    warm: dict[str, float] | None = None,
    tr_solver: str = "lsmr",
) -> dict[str, float]:
    """Bounded least squares (scipy's trust-region reflective) over named parameters; best of several starts
    (:func:`preferred_fit`: of equal fits, one off its bounds).

    ``residuals`` maps parameters (0-dim float64 tensors) to a 1-D residual tensor. ``jacobian`` is how its
    Jacobian is taken (``JACOBIANS``; None: the module's ``JACOBIAN``); a model that torch cannot differentiate
    (integer indexing by a parameter, a grid search inside) passes ``"2-point"`` whatever the default. ``warm``
    (a nested model's fitted values) replaces the default start for the parameters it names. ``tr_solver`` is
    scipy's trust-region step: ``"lsmr"`` (iterative, no factorisation of a tall Jacobian) or ``"exact"`` (a thin
    SVD); neither is faster everywhere (docs/bench/solver_choice.md), and two parameters or fewer always take exact
    steps.
    """
    jacobian = JACOBIAN if jacobian is None else jacobian
    if jacobian not in JACOBIANS:
        raise ValueError(f"jacobian={jacobian!r}: expected one of {', '.join(JACOBIANS)}")
    if not params:
        return {}
    names = [p.name for p in params]
    scale = torch.tensor([p.scale for p in params], dtype=torch.float64)
    low = np.array([p.low for p in params], dtype=np.float64) / scale.numpy()
    high = np.array([p.high for p in params], dtype=np.float64) / scale.numpy()

    def call(z: torch.Tensor) -> torch.Tensor:
        values = z * scale
        return residuals({n: values[i] for i, n in enumerate(names)})

    def fun(z: np.ndarray) -> np.ndarray:
        with torch.no_grad():
            return call(torch.from_numpy(z)).numpy()

    def jac(z: np.ndarray) -> np.ndarray:
        transform = torch.func.jacfwd if jacobian == "forward" else torch.func.jacrev
        return transform(call)(torch.from_numpy(z)).detach().numpy()

    fits: list[tuple[float, dict[str, float]]] = []
    default = {p.name: p.init for p in params}
    if warm:
        default.update({k: float(v) for k, v in warm.items() if k in default})
    for init in [default, *starts]:
        z0 = np.array([init.get(p.name, p.init) for p in params], dtype=np.float64) / scale.numpy()
        z0 = np.clip(z0, low + 1e-9 * (high - low), high - 1e-9 * (high - low))
        result = least_squares(
            fun,
            z0,
            jac="2-point" if jacobian == "2-point" else jac,
            bounds=(low, high),
            max_nfev=max_nfev,
            x_scale=1.0,
            # lsmr's 2-D subspace needs more than two parameters
            tr_solver=tr_solver if len(params) > 2 else "exact",
        )
        fits.append(
            (float(result.cost), {n: float(v) for n, v in zip(names, result.x * scale.numpy(), strict=True)})
        )
    return preferred_fit(params, fits)[1]


def preferred_fit(specs: Sequence[Param], fits: Sequence[tuple]) -> tuple:
    """The fit (a tuple: error, parameters, ...) with the lowest error; among fits whose errors agree within
    ``TIE_SHARE``, one with the fewest parameters at a bound of their search range. Where the data do not tell two
    fits apart, a parameter at its bound is where a start left it, not what the data ask for, and identification
    would reject the effect for it (session 30: a drawn stripe table whose rows fix no row time; fits from every
    start matched to 1e-6, and on the selection paths of two changes tried that session the one kept at a 0.37 us
    row time made selection withdraw exposure_overlap and write the base model, 178 rows held-out against 3.0)."""
    lowest = min(fit[0] for fit in fits)
    tied = [fit for fit in fits if ties_lowest(fit[0], lowest)]
    return min(
        tied,
        key=lambda fit: (sum(at_bound(fit[1][p.name], p.low, p.high) is not None for p in specs), fit[0]),
    )


class Problem:
    """Interface of one calibration problem. Subclasses set the class attributes and implement the methods."""

    attack: str = ""
    input_kind: str = ""
    units: str = ""
    base_model: str = ""
    extended_model: str = ""
    candidates: tuple[Effect, ...] = ()
    item_name: str = "items"  # what one item is, for the report ("table rows", "whole image pairs")
    heldout_definition: str = (
        "RMSE of the model fitted on the fit items, predicting the held-out items from their inputs alone"
    )
    # the largest group of new effects one selection step scores together (``forward_select``)
    joint_effects: int = 2
    # what inner cross-validation compares models by (``SELECTION_SCORES``); held-out figures are RMSE either way
    selection_score: str = "rmse"
    selection_score_reason: str = ""  # why, when it is not the RMSE (the report says it)
    # which effects a selection step prefers among groups whose scores tie within ``TIE_SHARE`` (the fit items do
    # not tell them apart; ``lowest_scoring``), earliest first, and why (the report says it); otherwise the lowest
    tie_preference: tuple[str, ...] = ()
    tie_preference_reason: str = ""

    @property
    def n_items(self) -> int:
        raise NotImplementedError

    def recording_facts(self) -> dict[str, str]:
        """Facts of the recording the models depend on, each with where it was read (the report's input)."""
        return {}

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        """Least-squares fit of the model with ``effects`` on ``items``; ``start``: a nested model's fit."""
        raise NotImplementedError

    @contextmanager
    def fits_kept(self) -> Iterator[None]:
        """Within the block, ``fit`` returns the fit it already made for the same effects, items and start.

        A fit is a function of those alone while the problem's data stay fixed (the starting points a problem scans
        for a model are kept from that model's first fit, so a repeat finds the same ones), and one calibration
        asks for many fits again: a selection pass after a withdrawal repeats the pass before it, with the same
        folds, seeds and starts, up to the step that took the withdrawn effect (kit case 62: 27 of 181 fits, 35% of
        the fit time, docs/bench/session55.md). A start is keyed by identity and kept with the entry, so that its id
        cannot be reused by another fit while the entry lives."""
        fit = self.fit
        shadowed = self.__dict__.get("fit")  # an enclosing block's
        kept: dict[tuple, tuple[Fit | None, Fit]] = {}

        def kept_fit(effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
            key = (frozenset(effects), tuple(int(i) for i in items), id(start))
            if key not in kept:
                kept[key] = (start, fit(effects, items, start))
            return kept[key][1]

        self.fit = kept_fit
        try:
            yield
        finally:
            if shadowed is None:
                del self.fit
            else:
                self.fit = shadowed

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        """Sum of squared errors (in the data's units) and number of values over ``items``."""
        raise NotImplementedError

    def rmse(self, fit: Fit, items: np.ndarray) -> float:
        total, count = self.squared_errors(fit, items)
        return math.sqrt(total / max(count, 1))

    def item_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per-item sums of squared errors and value counts (what item bootstraps resample)."""
        pairs = [self.squared_errors(fit, np.array([i])) for i in items]
        return np.array([p[0] for p in pairs], np.float64), np.array([p[1] for p in pairs], np.float64)

    def registered_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Problems with a per-item latent (``latent`` set): per-item squared errors with the latent fitted on each
        item itself - a registration figure reported next to the predictive one, never used to choose a model."""
        return None

    # a per-item quantity the attacker does not report and physics cannot predict (a pulse phase); when set,
    # ``squared_errors`` must score it predictively (marginalised over its fitted prior), never fit it per item
    latent: str | None = None

    def residual_sample(self, fit: Fit, items: np.ndarray, rng: np.random.Generator):
        """Residuals over ``items`` with the variables they may depend on (``structure.ResidualSample``), or
        None when this input offers nothing to test."""
        return None

    def item_label(self, item: int) -> str:
        """How a report names item ``item`` (structure.py's outlying-item test)."""
        return f"item {item}"

    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        """The fitted parameters of the model with ``effects`` (names and search bounds)."""
        return []

    def null_values(self, effect: str) -> dict[str, float]:
        """Parameter values at which ``effect`` reduces to the model without it ({} for a change of form)."""
        return {}

    def implied_statistic(
        self, effect: str, implied: str, params: dict[str, float]
    ) -> tuple[str, float, float]:
        """(name, value, null value) of the statistic by which the fitted ``params`` of a model holding ``effect``
        show the cause ``implied`` (``Effect.implies``)."""
        raise NotImplementedError(
            f"{type(self).__name__} declares no statistic for {implied} implied by {effect}"
        )

    def analyse(self, fit: Fit, items: np.ndarray) -> dict[str, dict[str, list[float]]]:
        """Residual RMSE binned by the variables that could explain it: ``{variable: {"x": [...], "rmse": [...]}}``."""
        return {}

    def evidence(self, effect: str, before: Fit, after: Fit, items: np.ndarray) -> str:
        return ""

    def transform_kwargs(self, fit: Fit) -> dict:
        """Constructor options of the attack transform reproducing ``fit`` (what ``calibrated.json`` carries)."""
        return {}

    def derived(self, fit: Fit) -> dict:
        """Physical quantities derived from the fitted parameters (e.g. a saturation radius)."""
        return {}

    def unoffered(self, fit_items: np.ndarray) -> dict[str, str]:
        """Candidates the fit items show no sign of, each with the measured reason: selection does not try them
        (``identify.select_and_identify``) and the report lists them. Read from the fit items only, as selection is."""
        return {}

    def figures(self, base: Fit, extended: Fit, items: np.ndarray, out_dir) -> list[str]:
        return []


# "rmse": every value's squared error pooled over the items; "mean_item_error": the mean over items of each item's
# own RMSE (an item's absolute error when it is one value), which a single unpredictable item cannot dominate
SELECTION_SCORES = {"rmse": "RMSE", "mean_item_error": "mean per-item error"}


def _check_score(kind: str) -> None:
    if kind not in SELECTION_SCORES:
        raise ValueError(f"selection score {kind!r} unknown; valid: {', '.join(SELECTION_SCORES)}")


def item_scores(kind: str, squared: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Per-item terms of the selection score ``kind``: squared-error sums ("rmse") or each item's RMSE."""
    _check_score(kind)
    squared = np.asarray(squared, np.float64)
    if kind == "rmse":
        return squared
    return np.sqrt(squared / np.maximum(np.asarray(counts, np.float64), 1.0))


def selection_value(kind: str, terms: np.ndarray, counts: np.ndarray) -> float:
    """The score from its per-item terms (``item_scores``) and the items' value counts."""
    return float(score_of_totals(kind, np.sum(terms), np.sum(counts), len(terms)))


def score_of_totals(kind: str, term_total, count_total, n_items: int):
    """The score ``kind`` from the totals of its per-item terms and value counts over ``n_items`` items; totals may
    be arrays (one score per bootstrap resample, ``identify.resummed_totals``)."""
    _check_score(kind)
    if kind == "rmse":
        return np.sqrt(np.asarray(term_total, np.float64) / np.maximum(count_total, 1.0))
    return np.asarray(term_total, np.float64) / n_items


def seeded_split(n_items: int, heldout: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(fit, held-out) item indices: a seeded random permutation; at least one item on each side."""
    if n_items < 2:
        raise ValueError(f"need at least 2 items (rows, tiles or image pairs) to hold any out, got {n_items}")
    if not 0.0 < heldout < 1.0:
        raise ValueError(f"--heldout must lie in (0, 1), got {heldout}")
    order = np.random.default_rng(seed).permutation(n_items)
    n_heldout = min(max(1, round(heldout * n_items)), n_items - 1)
    return np.sort(order[n_heldout:]), np.sort(order[:n_heldout])


def kfold(
    items: np.ndarray, folds: int, seed: int, max_train_items: int | None = None
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Seeded k-fold splits; training folds are subsampled to ``max_train_items`` (large tables fit fast)."""
    rng = np.random.default_rng(seed)
    order = rng.permutation(items)
    folds = max(2, min(folds, len(items)))
    parts = np.array_split(order, folds)
    splits = []
    for i in range(folds):
        train = np.concatenate(parts[:i] + parts[i + 1 :])
        if max_train_items is not None and len(train) > max_train_items:
            train = rng.choice(train, max_train_items, replace=False)
        splits.append((np.sort(train), np.sort(parts[i])))
    return splits


def selection_folds(
    fit_items: np.ndarray, folds: int, seed: int, max_train_items: int | None = None
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The selection's folds of the fit items (:func:`forward_select`), seeded ``seed + 1`` so that they draw from
    another stream than the calibration's split. Every reading of the fit side "refitted without each selection
    fold" (cross-fitted residuals, the photon-noise validation) uses these, so all of them see the same folds."""
    return kfold(fit_items, folds, seed + 1, max_train_items)


@dataclass
class Step:
    effects: list[str]
    validation_error: float  # the problem's selection score, inner cross-validated
    tried: dict[str, float]
    # per fit item: this model's term of the selection score (``item_scores``), the item scored in its validation fold
    item_errors: np.ndarray | None = None
    # a step inside a group of interacting effects kept together (forward_select): its effect is judged with the
    # whole group, from the step before the group to the step that completes it
    paired: bool = False
    # scored groups this step could not take, with the reason (groups_set_aside)
    set_aside: dict[str, str] = field(default_factory=dict)
    # scored groups whose score tied with the group the next step took (``lowest_scoring``): the fit items did not
    # tell them apart, and the problem's tie preference decided
    tied: list[str] = field(default_factory=list)
    # per scored group (by its label in ``tried``): its per-item terms, like ``item_errors``; what a simpler form
    # that lost this step to a richer one is judged by if the richer one is not identified (identify.py)
    tried_item_errors: dict[str, np.ndarray] = field(default_factory=dict)
    # the last step of a pass, per selected effect that no other selected effect builds on: the score and per-item
    # terms of the selected model without it, on the same folds (:func:`forward_select`); what it still brings once
    # every later step is in (identify.py, rule 2)
    without: dict[str, float] = field(default_factory=dict)
    without_item_errors: dict[str, np.ndarray] = field(default_factory=dict)
    # per effect in ``without``: the other selected effects whose own parameter sits at a bound in most fold fits of
    # the selected model without it (pinned_members), with why
    without_pinned: dict[str, dict[str, str]] = field(default_factory=dict)


def at_bound(value: float, low: float, high: float, tolerance: float = BOUND_TOLERANCE) -> str | None:
    """``"low"``/``"high"`` when ``value`` sits within ``tolerance`` x range of that bound, else None."""
    span = max(high - low, 1e-300)
    if value - low <= tolerance * span:
        return "low"
    if high - value <= tolerance * span:
        return "high"
    return None


def dependants(problem: Problem, effects: frozenset[str], effect: str) -> frozenset[str]:
    """The effects in ``effects`` that build on ``effect``, directly or through another one (``Effect.requires``)."""
    requires = requirements(problem)
    found: set[str] = set()
    frontier = {effect}
    while frontier:
        frontier = {e for e in effects if requires.get(e, set()) & frontier} - found
        found |= frontier
    return frozenset(found)


def leaves(problem: Problem, effects: frozenset[str]) -> list[str]:
    """The effects in ``effects`` that no other one in it builds on, by name."""
    return sorted(e for e in effects if not dependants(problem, effects, e))


def own_params(problem: Problem, effects: frozenset[str], effect: str) -> list[Param]:
    """The parameters ``effect`` itself adds to the model with ``effects``.

    Removing an effect also removes what builds on it (a stripe model without the exposure overlap has no
    detection threshold either), so the parameters the model loses with it are split: those of each dependant
    (found the same way, leaves first) belong to that dependant, the rest to ``effect``. A child at its bound
    therefore makes the child "not identified", never its parent."""
    below = dependants(problem, effects, effect)
    without = {p.name for p in problem.param_specs(effects - {effect} - below)}
    theirs = {p.name for child in below for p in own_params(problem, effects, child)}
    return [p for p in problem.param_specs(effects) if p.name not in without and p.name not in theirs]


def pinned_in_most_folds(spec: Param, fits: list[Fit]) -> str | None:
    """Why ``spec`` counts as pinned in ``fits`` (at one bound in more than half of them; a bound declared a
    physical limit excepted), or None."""
    sides = [at_bound(f.params[spec.name], spec.low, spec.high) for f in fits]
    for side, bound in (("low", spec.low), ("high", spec.high)):
        count = sides.count(side)
        if 2 * count > len(fits) and not spec.limit(side):
            return f"{spec.name} at its {side} bound {bound:g} in {count} of {len(fits)} folds"
    return None


def pinned_members(problem: Problem, model: frozenset[str], members, fits: list[Fit]) -> dict[str, str]:
    """The members of a scored group with an own parameter at one bound of its search range in most fold fits
    (:func:`pinned_in_most_folds`; a bound declared a physical limit, ``Param.low_limit``/``high_limit``,
    excepted), with why.

    Identification's rule 3 refuses to name such an effect (identify.py): its score measures the end of the range,
    not the camera. Selection applies the same rule before taking a group, so a pinned form cannot take the step
    that an identifiable alternative (another tone curve, a reflectance term) would have taken, only to be dropped
    afterwards with that alternative never tried. Most folds must agree, so one fold's stray optimum is no reason
    either way (seen: a power law at its bound 4 in three folds and at 3.94 in the fourth)."""
    pinned = {}
    for effect in members:
        reasons = (pinned_in_most_folds(spec, fits) for spec in own_params(problem, model, effect))
        reason = next((r for r in reasons if r), None)
        if reason:
            pinned[effect] = reason
    return pinned


def alternative_forms(problem: Problem, effect: str) -> list[str]:
    """The other forms of ``effect``'s term (``Effect.excludes``, in either direction), by name."""
    alternatives = {o for e in problem.candidates if e.name == effect for o in e.excludes}
    alternatives |= {e.name for e in problem.candidates if effect in e.excludes}
    return sorted(alternatives)


def simpler_forms(problem: Problem, effects: frozenset[str], effect: str) -> list[str]:
    """The alternative forms of ``effect``'s term with fewer own parameters in ``effects`` with the alternative in
    ``effect``'s place, by name."""
    mine = len(own_params(problem, effects, effect))
    return [
        a
        for a in alternative_forms(problem, effect)
        if len(own_params(problem, (effects - {effect}) | {a}, a)) < mine
    ]


def richer_alternatives(
    problem: Problem, chosen: frozenset[str], scored: dict[frozenset[str], object]
) -> list[tuple[frozenset[str], frozenset[str]]]:
    """(group, simpler) for every scored group holding one form of a term (``Effect.excludes``) where ``simpler``,
    the same group with an alternative form that has fewer own parameters, was scored too.

    Within their search ranges two forms of one term (a power-law tone curve and a shouldered one, which reaches the
    power law only in a limit outside its range) are not nested, so the richer form's lower score is no evidence by
    itself: on a camera the simpler form describes, the richer one still fits a hair better. Selection takes the
    richer form only by the margin under the simpler one (forward_select)."""
    pairs = []
    for group in scored:
        for effect in group:
            for alternative in simpler_forms(problem, chosen | group, effect):
                simpler = (group - {effect}) | {alternative}
                if simpler in scored:
                    pairs.append((group, simpler))
    return pairs


def groups_set_aside(
    problem: Problem,
    chosen: frozenset[str],
    scored: dict[frozenset[str], tuple[float, list[Fit], dict[int, float]]],
    labels: dict[frozenset[str], str],
    margin: float,
) -> tuple[dict[frozenset[str], str], dict[frozenset[str], frozenset[str]]]:
    """The scored groups a selection step may not take, with the reason: a member pinned at a bound in most fold
    fits (:func:`pinned_members`), or the richer of two forms of one term not ``margin`` under the same group with
    the simpler form (:func:`richer_alternatives`); and of the latter, each one's group with the simpler form."""
    set_aside: dict[frozenset[str], str] = {}
    for group, (_, fits, _) in scored.items():
        pinned = pinned_members(problem, chosen | group, group, fits)
        if pinned:
            set_aside[group] = "; ".join(f"{e}: {why}" for e, why in sorted(pinned.items()))
    unpinned = {g: v for g, v in scored.items() if g not in set_aside}
    outscored: dict[frozenset[str], frozenset[str]] = {}
    for group, simpler in richer_alternatives(problem, chosen, unpinned):
        if unpinned[group][0] > (1.0 - margin) * unpinned[simpler][0]:
            set_aside[group] = (
                f"not {100 * margin:.0f}% under {labels[simpler]}, the same model with the simpler form"
            )
            outscored[group] = simpler
    return set_aside, outscored


def stand_ins(
    outscored: dict[frozenset[str], frozenset[str]], scored: Mapping[frozenset[str], object]
) -> dict[frozenset[str], set[frozenset[str]]]:
    """Per group with the simpler of two forms of one term whose group with the richer form a step set aside for not
    beating it by the margin (``outscored``: richer group -> simpler group): the scored groups inside that richer group
    which hold the richer form. On the step's own scores the richer form does not pay beside the group's other
    members, so where it scores well without them it stands in for them, and the group is not measured against it
    (:func:`group_needs`). camsim's clipped sRGB cameras (master seeds 2735721871 and 752112996,
    docs/bench/session78.md): with the clip in, a shoulder was not 5% under the gamma curve, yet alone, 0.9-4.3%
    over the clip with the gamma, it was the best smaller group and kept that pair from the step; the shoulder took
    it, and the clip either joined it (the pair the step had set aside was written) or was missed."""
    found: dict[frozenset[str], set[frozenset[str]]] = {}
    for richer_group, simpler_group in outscored.items():
        richer = richer_group - simpler_group
        found.setdefault(simpler_group, set()).update(g for g in scored if richer <= g < richer_group)
    return found


def cross_validated(
    problem: Problem, effects: frozenset[str], splits, parents: list[Fit] | None
) -> tuple[float, list[Fit], dict[int, float]]:
    """The selection score over the folds, the fold fits, and each validation item's term of the score."""
    fits, per_item, terms, counts = [], {}, [], []
    for k, (train, val) in enumerate(splits):
        fit = problem.fit(effects, train, None if parents is None else parents[k])
        sq, n = problem.item_squared_errors(fit, val)
        terms.append(item_scores(problem.selection_score, sq, n))
        counts.append(n)
        per_item.update({int(i): float(e) for i, e in zip(val, terms[-1], strict=True)})
        fits.append(fit)
    score = selection_value(problem.selection_score, np.concatenate(terms), np.concatenate(counts))
    return score, fits, per_item


def forward_select(
    problem: Problem,
    fit_items: np.ndarray,
    *,
    seed: int,
    margin: float,
    folds: int = 4,
    max_train_items: int = 2500,
    withdrawn: frozenset[str] = frozenset(),
) -> tuple[frozenset[str], list[Step]]:
    """Forward selection of extensions by the inner k-fold validation score, each step needing a ``margin`` gain.
    ``withdrawn`` effects are not candidates (identify.select_and_identify: an earlier pass selected them and they
    were not identified, or the fit items show no sign of them, ``Problem.unoffered``).

    Only ``fit_items`` are used. Every step keeps each fit item's term of the score, so the effect size of a step
    can be bootstrapped over items (``identify.error_ratio``).

    Interacting effects can each be weak alone and strong together (a halo is invisible while the model cannot
    saturate; a reflectance term only pays in linear light): every step also scores each group of up to
    ``problem.joint_effects`` new effects. A group is taken over everything smaller only when it beats the best
    smaller one by the margin (its last effect earns its place given the others) and brings the margin over the
    current model once per effect in it that stands on its own - an effect that builds on another of the group
    (``requires``) only exists to carry it and adds no margin.

    Before that comparison, a scored group is set aside (``Step.set_aside``, with the reason) when a member's own
    parameter sits at a bound in most fold fits (:func:`pinned_members`), or when it holds the richer of two forms
    of one term and does not beat the same group with the simpler form by the margin (:func:`richer_alternatives`);
    the group with the simpler form is then not measured against the richer form's smaller groups, which stand in
    for its other members (:func:`stand_ins`).

    A step never revisits an earlier one, so an effect taken as the best of its step can stand in for one that
    only a later step could take: on the same folds, the selected model is scored without each effect no other
    selected effect builds on (``Step.without`` of the last step), for identification's rule 2, with the other
    effects a bound pins in that model's fold fits (``Step.without_pinned``)."""
    splits = selection_folds(fit_items, folds, seed, max_train_items)

    def aligned(per_item: dict[int, float]) -> np.ndarray:
        return np.array([per_item[int(i)] for i in fit_items], np.float64)

    chosen: frozenset[str] = frozenset()
    current, parents, per_item = cross_validated(problem, chosen, splits, None)
    steps = [Step([], current, {}, aligned(per_item))]
    fold_fits = [parents]  # per step
    while True:
        scored, labels = scored_groups(problem, chosen, withdrawn, splits, parents)
        if not scored:
            break
        steps[-1].tried = {labels[g]: v[0] for g, v in scored.items()}
        steps[-1].tried_item_errors = {labels[g]: aligned(v[2]) for g, v in scored.items()}
        set_aside, outscored = groups_set_aside(problem, chosen, scored, labels, margin)
        steps[-1].set_aside = {labels[g]: why for g, why in set_aside.items()}
        eligible = {g: v[0] for g, v in scored.items() if g not in set_aside}
        joint, tied = joint_group_taken(problem, eligible, current, margin, stand_ins(outscored, scored))
        if joint is not None:
            steps[-1].tied = [labels[g] for g in tied]
            # its prefixes may have been set aside alone: they are steps inside it all the same
            for prefix in steps_inside(joint, {g: v[0] for g, v in scored.items()}):
                steps.append(
                    Step(
                        sorted(chosen | prefix),
                        scored[prefix][0],
                        {},
                        aligned(scored[prefix][2]),
                        paired=True,
                    )
                )
                fold_fits.append(scored[prefix][1])
            taken = joint
        else:
            best_single, tied = lowest_scoring(problem, {g: v for g, v in eligible.items() if len(g) == 1})
            if best_single is None or eligible[best_single] > (1.0 - margin) * current:
                break
            taken = best_single
            steps[-1].tied = [labels[g] for g in tied]
        chosen = chosen | taken
        current, parents, per_item = scored[taken]
        steps.append(Step(sorted(chosen), current, {}, aligned(per_item)))
        fold_fits.append(parents)
    for effect in leaves(problem, chosen):
        rest = chosen - {effect}
        # warm start: the fold fits of the largest step nested in the model without it, as identification's refits
        nested = max(
            (k for k, s in enumerate(steps) if set(s.effects) <= rest), key=lambda k: len(steps[k].effects)
        )
        if set(steps[nested].effects) == rest:
            score, fits, terms = steps[nested].validation_error, fold_fits[nested], steps[nested].item_errors
        else:
            score, fits, without = cross_validated(problem, rest, splits, fold_fits[nested])
            terms = aligned(without)
        steps[-1].without[effect] = score
        steps[-1].without_item_errors[effect] = terms
        pinned = pinned_members(problem, rest, rest, fits)
        if pinned:
            steps[-1].without_pinned[effect] = pinned
    return chosen, steps


@dataclass(frozen=True)
class FormPass:
    """A selection pass repeated without the simpler form of a term the first pass took (:func:`select_forms`):
    what it selected and its last score, against the first pass's, and the steps of the pass not written."""

    without: str
    selected: list[str]
    validation_error: float
    first_selected: list[str]
    first_validation_error: float
    taken: bool
    # the pass whose model is not written: this one's steps, or the first pass's where this one is taken
    other_steps: list[Step] = field(repr=False, compare=False)


def richer_forms(problem: Problem, chosen: frozenset[str], effect: str) -> list[str]:
    """The alternative forms of ``effect``'s term with more own parameters in ``chosen`` with the alternative in
    ``effect``'s place, by name."""
    return [
        a
        for a in alternative_forms(problem, effect)
        if effect in simpler_forms(problem, (chosen - {effect}) | {a}, a)
    ]


def select_forms(
    problem: Problem,
    fit_items: np.ndarray,
    *,
    seed: int,
    margin: float,
    folds: int = 4,
    max_train_items: int = 2500,
    withdrawn: frozenset[str] = frozenset(),
) -> tuple[frozenset[str], list[Step], list[FormPass]]:
    """:func:`forward_select`, repeated without each simpler form of a term the pass took where a richer form is a
    candidate; a repeated pass that takes a richer form and ends ``margin`` under the first pass's last score is
    the selection (the lowest such one), and every repeated pass is returned as a :class:`FormPass`.

    Forward selection never revisits a step. The richer form of a term can need the effects that ride on it to pay,
    and without them its fits sit at a bound and are set aside, while the simpler form takes the step; once taken,
    it excludes the richer form for good. camsim's light projection cross-talk case on filmic cameras: a power-law
    gamma came first, because a shouldered curve without the reflectance term ran its knee to a hard clip, and the
    reflectance term then had no curve it could pay on (docs/bench/session64.md)."""
    options = dict(seed=seed, margin=margin, folds=folds, max_train_items=max_train_items)
    chosen, steps = forward_select(problem, fit_items, withdrawn=withdrawn, **options)
    first_error = steps[-1].validation_error
    repeats = {}  # simpler form -> (its richer forms, the repeat's selection, its steps)
    for simpler in sorted(chosen):
        richer = {r for r in richer_forms(problem, chosen, simpler) if r not in withdrawn}
        if richer:
            repeats[simpler] = (
                richer,
                *forward_select(problem, fit_items, withdrawn=withdrawn | {simpler}, **options),
            )
    eligible = {
        simpler: other_steps[-1].validation_error
        for simpler, (richer, other, other_steps) in repeats.items()
        if richer & other and other_steps[-1].validation_error <= (1.0 - margin) * first_error
    }
    taken = min(eligible, key=eligible.get, default=None)
    passes = [
        FormPass(
            simpler,
            sorted(other),
            other_steps[-1].validation_error,
            sorted(chosen),
            first_error,
            simpler == taken,
            steps if simpler == taken else other_steps,
        )
        for simpler, (_, other, other_steps) in repeats.items()
    ]
    if taken is None:
        return chosen, steps, passes
    _, other, other_steps = repeats[taken]
    return other, other_steps, passes


def scored_groups(
    problem: Problem,
    chosen: frozenset[str],
    withdrawn: frozenset[str],
    splits,
    parents: list[Fit],
) -> tuple[dict[frozenset[str], tuple[float, list[Fit], dict[int, float]]], dict[frozenset[str], str]]:
    """Every group of up to ``problem.joint_effects`` new effects that is a valid model on top of ``chosen``,
    cross-validated: new effects -> (score, fold fits, per-item terms), and the name each is reported by
    (:func:`group_label`)."""
    requires = requirements(problem)
    open_names = [e.name for e in problem.candidates if e.name not in chosen | withdrawn]
    scored: dict[frozenset[str], tuple[float, list[Fit], dict[int, float]]] = {}
    labels: dict[frozenset[str], str] = {}
    for size in range(1, problem.joint_effects + 1):
        for members in itertools.combinations(open_names, size):
            model = chosen | set(members)
            if any(not requires[e] <= model for e in members) or exclusive(problem.candidates, model):
                continue
            label = group_label(members, chosen, requires)
            group = frozenset(members)
            # warm start: the fold fits of the group without its last member (a pair: its first effect's)
            start = scored.get(frozenset(label[:-1]), (None, parents))[1]
            scored[group] = cross_validated(problem, model, splits, start)
            labels[group] = "+".join(label)
    return scored, labels


def joint_group_taken(
    problem: Problem,
    eligible: dict[frozenset[str], float],
    current: float,
    margin: float,
    not_compared: dict[frozenset[str], set[frozenset[str]]],
) -> tuple[frozenset[str] | None, list[frozenset[str]]]:
    """The group of two or more new effects a step takes, or None, and the groups its score tied with
    (:func:`lowest_scoring`): of the groups under what they need, the one with the lowest score. A group needs
    ``margin`` under the best smaller eligible group nested in it or earning a step itself (:func:`group_needs`), but
    those ``not_compared`` with it (:func:`stand_ins`), and, over the ``current`` score, the margin once per member
    that stands on its own (one that builds on another member only carries it).

    Lowest score, not furthest under its need: a pair far under its need can be the first step of a worse model
    (camsim projection_additive on filmic cameras: additive light + a power-law gamma, then the reflectance term
    pinned on the power law's curve, where additive light + shoulder + reflectance beat that pair by 19%), and a
    larger group under its need has already beaten by the margin every smaller one the step could take."""
    needed = group_needs(requirements(problem), eligible, current, margin, not_compared)
    return lowest_scoring(problem, {g: eligible[g] for g in needed if eligible[g] <= needed[g]})


def lowest_scoring(
    problem: Problem, scores: dict[frozenset[str], float]
) -> tuple[frozenset[str] | None, list[frozenset[str]]]:
    """The group with the lowest score (None when there is none), and the other groups within ``TIE_SHARE`` of it.
    Among tied groups the one with the effect earliest in ``problem.tie_preference`` is taken, then the lowest: a
    tie is the fit items not telling two models apart, and which one won it was rounding (drawn stripe camera
    1804228398, lit frames: a detection threshold and a negative integration offset scored 0.852099314 and
    0.852099313 rows, the order flipped by a rounding fix in the overlap kernel, and the two predict the held-out
    rows to 10.0 and 116 rows)."""
    if not scores:
        return None, []
    lowest = min(scores.values())
    tied = [g for g, v in scores.items() if ties_lowest(v, lowest)]
    preference = {name: rank for rank, name in enumerate(problem.tie_preference)}

    def rank(group: frozenset[str]) -> tuple[int, float]:
        preferred = min((preference.get(e, len(preference)) for e in group), default=len(preference))
        return preferred, scores[group]

    taken = min(tied, key=rank)
    return taken, sorted((g for g in tied if g != taken), key=rank)


def group_needs(
    requires: dict[str, set[str]],
    eligible: dict[frozenset[str], float],
    current: float,
    margin: float,
    not_compared: dict[frozenset[str], set[frozenset[str]]],
) -> dict[frozenset[str], float]:
    """The score each eligible group of two or more new effects must reach to earn a step
    (:func:`joint_group_taken`), by size.

    A group is measured against the smaller groups nested in it, so that each member earns its place beside the
    others, and against the smaller rivals that earn a step themselves: a single ``margin`` under ``current``, a
    group under its own need. A rival that earns no step is no model the step could take, and measuring against it
    made the step take something worse than both (camsim projection_additive 2446689515 on a filmic camera with a
    colour correction matrix, docs/bench/session99.md: additive light + matrix, 4.0% under light alone, kept
    light + reflectance + shoulder, 7.5% under light alone and 3.6% under that pair, from the step, and light alone
    was taken)."""
    earning = {g for g, v in eligible.items() if len(g) == 1 and v <= (1.0 - margin) * current}
    needed = {}
    for group in sorted((g for g in eligible if len(g) >= 2), key=len):
        skipped = not_compared.get(group, set())
        smaller = min(
            (
                v
                for g, v in eligible.items()
                if len(g) < len(group) and g not in skipped and (g < group or g in earning)
            ),
            default=math.inf,
        )
        standing = max(1, sum(1 for e in group if not requires[e] & group))
        needed[group] = min((1.0 - margin) * smaller, (1.0 - standing * margin) * current)
        if eligible[group] <= needed[group]:
            earning.add(group)
    return needed


def steps_inside(joint: frozenset[str], scores: dict[frozenset[str], float]) -> list[frozenset[str]]:
    """The steps inside a group taken at once: the order whose every prefix was scored, the best-scoring prefixes
    first (a pair: the better of its two effects alone)."""
    orders = [
        [frozenset(order[: k + 1]) for k in range(len(order) - 1)] for order in itertools.permutations(joint)
    ]
    return min((o for o in orders if all(p in scores for p in o)), key=lambda o: [scores[p] for p in o])


def requirements(problem: Problem) -> dict[str, set[str]]:
    """Each candidate effect's ``requires``, by name."""
    return {e.name: set(e.requires) for e in problem.candidates}


def group_label(members, chosen: frozenset[str], requires: dict[str, set[str]]) -> tuple[str, ...]:
    """A group's members in a fixed order: those valid alone on the current model first, each part by name."""
    alone = sorted(e for e in members if requires[e] <= chosen)
    return tuple(alone + sorted(e for e in members if e not in alone))


def fit_chain(problem: Problem, steps: list[Step], items: np.ndarray) -> list[Fit]:
    """Fits of the base and of every model selection kept, each started from the previous one."""
    fits = [problem.fit(frozenset(), items)]
    for step in steps[1:]:
        fits.append(problem.fit(frozenset(step.effects), items, fits[-1]))
    return fits


# a variable with at most MAX_LEVELS distinct values, each seen MIN_PER_LEVEL times on average, is binned by level
MAX_LEVELS = 16
MIN_PER_LEVEL = 3


def bin_index(x: np.ndarray, bins: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Each value's bin and the bins' centres: one bin per distinct value when ``x`` has few values, else ``bins``
    quantile bins.

    A variable is binned by its levels when it has at most ``bins`` of them, or at most ``MAX_LEVELS`` seen
    ``MIN_PER_LEVEL`` times each on average (a table's settings): quantile bins would merge neighbouring levels, and
    an effect need not be smooth across them (a beat with the frame rate changes sign between neighbouring laser
    frequencies, and two merged levels cancel)."""
    x = np.asarray(x, dtype=np.float64).ravel()
    levels = np.unique(x)
    if len(levels) <= bins or (len(levels) <= MAX_LEVELS and len(x) >= MIN_PER_LEVEL * len(levels)):
        return np.searchsorted(levels, x), levels
    edges = np.unique(np.quantile(x, np.linspace(0, 1, bins + 1)))
    index = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, len(edges) - 2)
    return index, 0.5 * (edges[:-1] + edges[1:])


def binned_rmse(x: np.ndarray, residual: np.ndarray, bins: int = 8) -> dict[str, list[float]]:
    """RMSE of ``residual`` per bin of ``x`` (:func:`bin_index`)."""
    index, centres = bin_index(x, bins)
    residual = np.asarray(residual, dtype=np.float64).ravel()
    counts = np.bincount(index, minlength=len(centres))
    squares = np.bincount(index, weights=residual**2, minlength=len(centres))
    kept = counts > 0
    return {
        "x": centres[kept].tolist(),
        "rmse": np.sqrt(squares[kept] / counts[kept]).tolist(),
        "count": counts[kept].tolist(),
    }
