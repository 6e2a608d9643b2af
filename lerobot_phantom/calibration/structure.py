"""Is anything left in the held-out residual that the selected model does not explain?

Run on the held-out residual of the model that is written (base + identified effects). Two kinds of test:

- **dependence on a variable** (position in the frame, intensity, brightness, channel, the table's settings, the
  local detail of a recorded attack pattern: ``frame_models.common.pattern_detail``): the
  share of the residual's variance explained by its mean per bin of the variable (eta squared): up to 8 quantile
  bins, or one bin per level for a variable of few distinct values (``core.bin_index``: a table's settings).
  Structure remains when the lower end of the 90% item-bootstrap interval of eta squared exceeds both
  ``MIN_EXPLAINED`` (2% of the residual variance) and what chance alone gives with this many values: the
  ``1 - FAMILY_ALPHA / k`` quantile of eta squared when the residuals are permuted (``PERMUTATIONS`` permutations,
  each scored against all ``k`` variables tested). Dividing by ``k`` (Bonferroni) holds the chance that a residual
  without structure is reported as structured near ``FAMILY_ALPHA`` however many variables a problem offers. On
  2000 null stripe tables (five settings, 18 held-out rows; ``docs/bench/stripe_null_structure.py``) structure
  was reported on 14 at the 99th percentile per variable, on 2 at this quantile;
- **dependence of the variance on position** (frame pairs): the same test on the residual's size over the standard
  deviation the sensor-noise model of ``noise.py`` gives at its signal, relative to its mean (``variance_tests``):
  a zero-mean effect the model lacks (laser speckle, a blur growing from a centre) leaves the mean alone and shows
  in the variance;
- **displaced lines** (frame pairs): how much of the residual a displacement of each row along the row (of each
  column along the column) explains, as read independently in each half of the line (``displacement_tests``). A
  measured frame whose lines hold the predicted content moved by a fraction of a pixel or more leaves a residual of
  zero mean in every bin, largest at edges, which binned means dilute among the flat values;
- **correlation between neighbours** ``LAG`` values apart along rows and along columns of a frame (a residual
  that is a smooth image, not noise), or between a table's row and the row nearest to it in the table's inputs
  (``NeighbourPairs.pairing``; colour triples: ``projection.nearest_surface_colour``): structure remains
  when the interval's lower end exceeds ``MIN_NEIGHBOUR_CORR``. Sensor processing (demosaicing, compression)
  correlates neighbours at lags of one or two pixels, hence lag 3. Rows whose inputs nearly agree and whose errors
  agree too leave a residual that is a function of the inputs, which binned means by one input at a time dilute
  when it changes faster than a bin or with a combination of inputs (the SLAP bottle: docs/bench/session65.md).
  Where pairs come in groups (``NeighbourPairs.groups``: a table's projected colours), the finding names
  the group whose pairs share the most residual. Pairs that share a row (two rows nearest to one third) are not
  independent: the bootstrap resamples each cluster of rows linked as nearest neighbours whole
  (``NeighbourPairs.clusters``);

- **items outside the model's error distribution**: a held-out item whose error exceeds ``OUTLIER_FACTOR`` times
  the largest error of any fit item (exchangeable items exceed that largest error with probability 1/(n_fit + 1)
  each, before the fit's own optimism), when such items carry at least ``OUTLIER_SHARE`` of the held-out squared
  error: the model fails on a few items, not everywhere, and the finding names them (``Problem.item_label``: a
  stripe table's row with its settings and, when the table has it, its frames' spread).

Every finding also needs to matter: the structured part of the residual (eta squared, the lag correlation or the
outlying items' share, times the residual's mean square) must be at least ``MIN_SHARE_OF_BASE`` (0.5%) of the
base model's held-out mean squared error - a remnant of a model that is otherwise right is not reported as a
missing cause.

An item bootstrap over a few held-out items is no interval: over two, its 5% end is the weaker item's own value
(a quarter of the draws hold it twice). With fewer than ``MIN_TESTED_ITEMS`` held-out items (two of eight frame
pairs), the fit items join the sample with their cross-fitted residuals: the written model refitted on the fit
items without each of the selection's folds predicts the fold it left out, so no residual comes from a fit that saw
its item. The fit items did inform which effects were selected, so their residuals lean toward the written model:
a conservative sample for finding what it misses, never a generous one. The outlying-item test and the base model's
mean squared error stay held-out figures.

A problem supplies its residuals through ``Problem.residual_sample`` (None: not tested). The finding names what
structure is left and where; it never names a library effect.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from lerobot_phantom.calibration.core import Fit, bin_index, selection_folds
from lerobot_phantom.calibration.identify import RESUMMED_DRAWS, percentile_interval, resummed_totals
from lerobot_phantom.calibration.noise import NoiseSample, fit_variance, model_variance

BINS = 8
MIN_EXPLAINED = 0.02
MIN_NEIGHBOUR_CORR = 0.25
MIN_SHARE_OF_BASE = 0.005
LAG = 3
FAMILY_ALPHA = 0.01
PERMUTATIONS = 2000
OUTLIER_FACTOR = 2.0
OUTLIER_SHARE = 0.5
MIN_FIT_ITEMS = 5  # a largest fit error over fewer items is no reference
LINE_BLOCK = 8  # pixels: a line's two halves for the displacement test alternate in blocks this long
MIN_TESTED_ITEMS = 5  # fewer held-out items than this are joined by the fit items' cross-fitted residuals


@dataclass
class NeighbourPairs:
    """One kind of neighbouring residuals: per item, the residuals of its pairs' two sides."""

    pairs: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    # what is paired, where it is not two values ``LAG`` apart along a line of a frame (a table's rows)
    pairing: str | None = None
    # per item's pairs: the part of the inputs they share (a table's projected colour), so that a finding can say
    # where the pairs agree most
    groups: list[str] | None = None
    # per item's pairs: the cluster of pairs it shares residuals with (a table's rows linked as nearest neighbours:
    # two rows nearest to one third share its residual), resampled together by the interval's bootstrap; None: the
    # items are independent
    clusters: list[int] | None = None

    def joined(self, other: NeighbourPairs) -> NeighbourPairs:
        clusters = None
        if self.clusters is not None:
            offset = max(self.clusters, default=-1) + 1
            clusters = self.clusters + [offset + c for c in other.clusters]
        return NeighbourPairs(
            self.pairs + other.pairs,
            self.pairing,
            None if self.groups is None else self.groups + other.groups,
            clusters,
        )

    def resampled_columns(self, columns: np.ndarray) -> np.ndarray:
        """What the interval's bootstrap draws: each item's ``moment_columns`` (``columns``), or their sums per
        cluster."""
        if self.clusters is None:
            return columns
        cluster, index = np.unique(np.asarray(self.clusters), return_inverse=True)
        sums = np.zeros((len(cluster), columns.shape[1]))
        np.add.at(sums, index, columns)
        return sums


@dataclass
class ResidualSample:
    """Held-out residuals per item, with the variables they may depend on and neighbouring residual pairs."""

    residual: list[np.ndarray]
    covariates: dict[str, list[np.ndarray]]
    neighbours: dict[str, NeighbourPairs] = field(default_factory=dict)
    # frame pairs: per item, its unclipped values' sensor-noise terms (``noise.NoiseSample``) and their position
    noise: list[NoiseSample] = field(default_factory=list)
    noise_position: dict[str, list[np.ndarray]] = field(default_factory=dict)
    # frame pairs: per direction ("rows", "columns"), each item's ``line_terms``
    lines: dict[str, list[np.ndarray]] = field(default_factory=dict)

    def joined(self, other: ResidualSample) -> ResidualSample:
        """This sample's items followed by ``other``'s (the same variables)."""
        return ResidualSample(
            self.residual + other.residual,
            {name: values + other.covariates[name] for name, values in self.covariates.items()},
            {name: pairs.joined(other.neighbours[name]) for name, pairs in self.neighbours.items()},
            self.noise + other.noise,
            {name: values + other.noise_position[name] for name, values in self.noise_position.items()},
            {name: values + other.lines[name] for name, values in self.lines.items()},
        )


def cross_fitted_sample(problem, fit: Fit, splits, rng: np.random.Generator) -> ResidualSample:
    """Residuals of each split's left-out items under ``fit``'s model refitted on its training items. Cold starts: a
    start at ``fit`` would carry what it learnt from the items predicted."""
    parts = [
        problem.residual_sample(problem.fit(fit.effects, train), left_out, rng) for train, left_out in splits
    ]
    return functools.reduce(ResidualSample.joined, parts)


# Both statistics are functions of sums over items (per-bin residual sums and counts, sums of squares and products):
# the estimate is the statistic of all items' totals, and the intervals re-sum ``identify.RESUMMED_DRAWS`` item
# resamples (200 resampled draws until session 44).


def binned_columns(residual: np.ndarray, bins: np.ndarray, n_bins: int) -> np.ndarray:
    """One item's terms of eta squared: its residual sum per bin, its value count per bin, its sum of squares."""
    return np.concatenate(
        [
            np.bincount(bins, weights=residual, minlength=n_bins),
            np.bincount(bins, minlength=n_bins),
            [np.sum(residual**2)],
        ]
    )


def explained_share_of_totals(totals: np.ndarray, n_bins: int) -> np.ndarray:
    """eta squared, the share of the residual's variance (about 0) explained by its mean per bin, from the totals of
    ``binned_columns`` over a sample's items (one sample per row)."""
    sums, counts, squares = totals[:, :n_bins], totals[:, n_bins : 2 * n_bins], totals[:, -1]
    between = np.sum(np.where(counts > 0, sums**2 / np.maximum(counts, 1.0), 0.0), axis=1)
    return np.where(squares > 0, between / np.maximum(squares, 1e-300), 0.0)


def moment_columns(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """One item's terms of a correlation: value count, sums of a, b, a^2, b^2 and a*b."""
    return np.array([len(a), a.sum(), b.sum(), (a * a).sum(), (b * b).sum(), (a * b).sum()], dtype=np.float64)


def correlation_of_totals(totals: np.ndarray) -> np.ndarray:
    """Pearson's correlation from the totals of ``moment_columns`` over a sample's items (one per row); 0 where a side
    is constant (its centred sum of squares at most 1e-12 of its raw one: rounding) or has fewer than 3 values."""
    n, a, b, aa, bb, ab = totals.T
    safe_n = np.maximum(n, 1.0)
    var_a, var_b = aa - a * a / safe_n, bb - b * b / safe_n
    valid = (n >= 3) & (var_a > 1e-12 * aa) & (var_b > 1e-12 * bb)
    r = (ab - a * b / safe_n) / np.sqrt(np.where(valid, var_a * var_b, 1.0))
    return np.where(valid, np.clip(r, -1.0, 1.0), 0.0)


def _where(values: np.ndarray, residual: np.ndarray, bins: np.ndarray, tested: str = "mean residual") -> str:
    sums, counts = np.bincount(bins, weights=residual), np.bincount(bins)
    means = np.where(counts > 0, sums / np.maximum(counts, 1), 0.0)
    worst = int(np.argmax(np.abs(means)))
    inside = values[bins == worst]
    return f"largest {tested} {means[worst]:+.3g} for values {inside.min():.3g}-{inside.max():.3g}"


def residual_structure(
    problem,
    fit,
    items: np.ndarray,
    *,
    base_mse: float,
    rng: np.random.Generator,
    fit_items: np.ndarray | None = None,
    folds: int | None = None,
    seed: int = 0,
) -> dict:
    """The tests of the module docstring on ``fit``'s residual over ``items`` (``base_mse``: the base model's
    held-out mean squared error; ``fit_items``: the items ``fit`` was fitted on, the reference of the outlying-item
    test, which runs only with them; ``folds`` and ``seed``: the selection's, for the cross-fitted residuals of the
    fit items that join fewer than ``MIN_TESTED_ITEMS`` held-out items); a JSON-ready dict."""
    sample = problem.residual_sample(fit, items, rng)
    tested_on, residual = (
        "held-out residual of the written model (base + identified effects)",
        "held-out residual",
    )
    few = len(items) < MIN_TESTED_ITEMS
    if sample is not None and few and folds is not None and fit_items is not None and len(fit_items) > 1:
        splits = selection_folds(fit_items, folds, seed)
        sample = sample.joined(cross_fitted_sample(problem, fit, splits, rng))
        tested_on += (
            f", and (fewer than {MIN_TESTED_ITEMS} held-out items) the {len(fit_items)} fit items' residuals under "
            f"the same model refitted without each of {len(splits)} folds"
        )
        residual = "held-out and cross-fitted residuals"
    out: dict = {
        "tested_on": tested_on,
        "rule": f"a variable's binned mean explains > max({MIN_EXPLAINED}, the permutation null's 1 - "
        f"{FAMILY_ALPHA}/k quantile, k the variables tested) of the residual variance at the low end of a 90% "
        f"item-bootstrap interval (frame pairs: also the residual's size over the sensor-noise model's standard "
        f"deviation, relative to its mean, by row and column; and the share of the residual a displacement of each "
        f"row along the row, or column along the column, explains as read in each half of the line, > "
        f"{MIN_EXPLAINED} at the low end); "
        f"neighbours (in a frame {LAG} values apart along a line; in a table a row and the row nearest to it in "
        f"the table's inputs, as the finding's pairing says) correlate > {MIN_NEIGHBOUR_CORR} at its low end; items "
        "whose error exceeds "
        f"{OUTLIER_FACTOR:g}x the largest fit item's carry >= {100 * OUTLIER_SHARE:.0f}% of the held-out squared "
        f"error; and the structured part is >= {100 * MIN_SHARE_OF_BASE:.1f}% of the base model's "
        "held-out mean squared error",
        "tests": [],
        "structure_remains": False,
        "summary": "",
    }
    if sample is None or not sample.residual:
        out["summary"] = "not tested (this input has no residual sample)"
        return out
    out["tests"] = sample_tests(sample, base_mse, rng)
    if fit_items is not None:
        out["tests"] += outlying_item_tests(
            problem, fit, items, fit_items, share_of_base_mse(sample, base_mse)
        )
    found = [t for t in out["tests"] if t["significant"]]
    out["structure_remains"] = bool(found)
    out["summary"] = structure_summary(found, residual)
    return out


def share_of_base_mse(sample: ResidualSample, base_mse: float) -> Callable[[float], float]:
    """A statistic that is a share of ``sample``'s mean square -> its share of the base model's ``base_mse``."""
    mean_square = float(np.mean(np.concatenate(sample.residual) ** 2))
    return lambda statistic: statistic * mean_square / max(base_mse, 1e-300)


def sample_tests(sample: ResidualSample, base_mse: float, rng: np.random.Generator) -> list[dict]:
    """Every test of the module docstring that reads a residual sample alone (all but the outlying items)."""
    share_of_base = share_of_base_mse(sample, base_mse)
    family = len(sample.covariates) + len(sample.noise_position)
    return (
        dependence_tests(sample, share_of_base, rng, family=family)
        + variance_tests(sample, base_mse, rng, family=family)
        + neighbour_tests(sample, share_of_base, rng)
        # last of the tests that draw from rng: the others' draws are those of a sample without lines
        + displacement_tests(sample, share_of_base, rng)
    )


def fit_items_structure(
    problem,
    fit: Fit,
    fit_items: np.ndarray,
    *,
    base_mse: float,
    folds: int,
    seed: int,
    rng: np.random.Generator,
) -> dict:
    """The sample tests on the fit items' cross-fitted residuals alone (the written model refitted without each of
    the selection's folds predicts the fold it left out; ``base_mse``: the base model's cross-validated mean squared
    error over the fit items): what the fit side of a calibration may know of the structure its model leaves,
    with no held-out item read. A JSON-ready dict like :func:`residual_structure`'s."""
    splits = selection_folds(fit_items, folds, seed)
    sample = cross_fitted_sample(problem, fit, splits, rng)
    tests = sample_tests(sample, base_mse, rng) if sample is not None and sample.residual else []
    found = [t for t in tests if t["significant"]]
    return {
        "tested_on": f"the {len(fit_items)} fit items' residuals under the written model refitted without each of "
        f"{len(splits)} folds",
        "tests": tests,
        "structure_remains": bool(found),
        "summary": structure_summary(found, "cross-fitted residual of the fit items"),
    }


def dependence_tests(
    sample: ResidualSample,
    share_of_base: Callable[[float], float],
    rng: np.random.Generator,
    family: int | None = None,
    tested: str = "mean residual",
) -> list[dict]:
    """Per covariate: the share of the residual variance its binned mean explains, against the permutation null
    (its quantile corrected for ``family`` variables tested in all, by default this sample's covariates);
    ``tested`` names a bin's mean in ``where``."""
    residual_all = np.concatenate(sample.residual)
    values = {name: np.concatenate(per_item) for name, per_item in sample.covariates.items()}
    bins = {name: bin_index(v, BINS)[0] for name, v in values.items()}
    n_bins = {name: int(b.max()) + 1 for name, b in bins.items()}
    # one permutation of the residuals scores every variable: row j of null_shares is one draw of chance for all
    null_shares = np.empty((PERMUTATIONS, len(bins)))
    for j in range(PERMUTATIONS if bins else 0):
        permuted = rng.permutation(residual_all)
        null_shares[j] = [
            explained_share_of_totals(binned_columns(permuted, bins[name], n)[None], n)[0]
            for name, n in n_bins.items()
        ]
    quantile = 1.0 - FAMILY_ALPHA / max(family or len(bins), 1)
    starts = np.concatenate([[0], np.cumsum([len(r) for r in sample.residual])])
    spans = [slice(starts[i], starts[i + 1]) for i in range(len(sample.residual))]
    tests = []
    for column, (name, values_all) in enumerate(values.items()):
        bins_all, n = bins[name], n_bins[name]
        columns = np.array(
            [
                np.concatenate(
                    [
                        binned_columns(residual_all[span], bins_all[span], n),
                        moment_columns(values_all[span], residual_all[span]),
                    ]
                )
                for span in spans
            ]
        )
        every_item = columns.sum(axis=0, keepdims=True)
        totals = resummed_totals(columns, draws=RESUMMED_DRAWS, rng=rng)
        eta = percentile_interval(
            float(explained_share_of_totals(every_item[:, : 2 * n + 1], n)[0]),
            explained_share_of_totals(totals[:, : 2 * n + 1], n),
        )
        r = percentile_interval(
            float(correlation_of_totals(every_item[:, 2 * n + 1 :])[0]),
            correlation_of_totals(totals[:, 2 * n + 1 :]),
        )
        null = null_shares[:, column]
        chance = float(np.quantile(null, quantile))
        significant = (
            eta.low > max(MIN_EXPLAINED, chance) and share_of_base(eta.estimate) >= MIN_SHARE_OF_BASE
        )
        tests.append(
            {
                "variable": name,
                "statistic": "eta2",
                "value": eta.estimate,
                "interval": eta.as_dict(),
                "chance": chance,
                "chance_quantile": quantile,
                "share_of_base_mse": share_of_base(eta.estimate),
                "p_value": float((1 + np.sum(null >= eta.estimate)) / (1 + PERMUTATIONS)),
                "r": r.as_dict(),
                "significant": bool(significant),
                "where": _where(values_all, residual_all, bins_all, tested),
            }
        )
    return tests


def variance_tests(
    sample: ResidualSample, base_mse: float, rng: np.random.Generator, family: int | None = None
) -> list[dict]:
    """Frame pairs: does the residual's size, relative to the sensor-noise model (``noise.py``: quantisation,
    compression where the frame has detail, read and photon noise at each value's signal), depend on where the
    value sits in the frame? Sensor noise at a given signal does not, so noise that does is something acting in
    places that the model leaves out with zero mean (laser speckle, a rotation's blur growing from its centre). The
    dependence test runs on Levene's absolute form ``y = a / mean(a) - 1``, ``a = |residual| / modelled sd`` (0 in
    every bin when the noise model holds up to a common scale). Squared residuals leave a sample's largest values to
    carry eta2, so an item bootstrap without the strongest pair loses it: on camsim's strip speckle (ten master
    seeds) their low end was 0.0135-0.0376, four under the floor, the absolute form's 0.0619-0.1107; of 70 null
    cases two are above the floor with the absolute form, one with squares, all EM colour strips (the colour map
    multiplies the noise of the rows it decodes: docs/bench/session73/variance_statistic*.txt; read at the sensor
    values the map took, ``FrameProblem.noise_sources``, one of the two stays above it, its excess not on the
    decoded rows: docs/bench/session74.md). Only position is tested, since the paper's digital forms scale
    the attacked frame's noise with the intensity (a blend by 1 - a) and demosaicing gives green less noise than
    red and blue (eta2 up to 0.04 by intensity or channel on the independent simulator's null cases, at most 0.008
    by row or column: docs/bench/session46/variance_probe.txt, squared form). The size of a finding: a bin whose
    ``a`` is ``1 + d`` times the sample's mean holds ``(1 + d)^2 - 1`` times the variance more; the bins'
    root-mean-square ``d`` turned into that excess, times the mean modelled variance (grey levels^2).
    An ISP's lens-shading correction (a digital gain rising toward the corners) also makes noise grow with position
    at a given output level; the test reports that as well, as what it is: variance the noise model does not place."""
    joined = NoiseSample.join(sample.noise) if sample.noise else None
    if joined is None or len(joined.residual) < 2 * BINS:  # no frame pairs, or (nearly) every value clipped
        return []
    variance = model_variance(joined, fit_variance(joined, True))
    size = np.abs(joined.residual) / np.sqrt(variance)
    excess = np.split(
        size / max(float(np.mean(size)), 1e-300) - 1.0,
        np.cumsum([len(p.residual) for p in sample.noise])[:-1],
    )
    mean_square_excess = float(np.mean(np.concatenate(excess) ** 2))

    def share_of_base(statistic: float) -> float:
        size_excess = math.sqrt(max(statistic, 0.0) * mean_square_excess)
        return ((1.0 + size_excess) ** 2 - 1.0) * float(np.mean(variance)) / max(base_mse, 1e-300)

    tests = dependence_tests(
        ResidualSample(excess, sample.noise_position),
        share_of_base,
        rng,
        family=family,
        tested="size over the noise model's (|residual| / modelled sd, over its mean, - 1)",
    )
    for test in tests:
        test["variable"] = f"variance_by_{test['variable']}"
        test["statistic"] = "eta2 of the noise size excess"
    return tests


def line_terms(residual: np.ndarray, predicted: np.ndarray) -> dict[str, np.ndarray]:
    """Per direction, per line of a frame pair (a row for "rows", a column for "columns"): the sums over the
    channels and each half of the line (alternate blocks of ``LINE_BLOCK`` pixels) of ``residual * g`` and ``g^2``,
    ``g`` the predicted frame's gradient along the line (``np.gradient``, grey levels per pixel), and the line's sum
    of squared residuals: an array (lines, 5) per direction. Inputs are (channels, height, width), grey levels."""
    residual, predicted = np.asarray(residual, np.float64), np.asarray(predicted, np.float64)
    out = {}
    for direction, axis in (("rows", 2), ("columns", 1)):
        gradient = np.gradient(predicted, axis=axis)
        r, g = (np.moveaxis(a, axis, 2) for a in (residual, gradient))  # lines along the last axis
        # interleaved blocks, not the line's two ends: an edge in one end only leaves the other end nothing to read
        second = (np.arange(r.shape[2]) // LINE_BLOCK) % 2 == 1
        halves = [
            [np.sum(a[:, :, part] * b[:, :, part], axis=(0, 2)) for a, b in ((r, g), (g, g))]
            for part in (~second, second)
        ]
        out[direction] = np.stack([*halves[0], *halves[1], np.sum(r * r, axis=(0, 2))], axis=1)
    return out


def displacement_columns(terms: np.ndarray) -> np.ndarray:
    """One item's terms of the displacement test from its ``line_terms`` of one direction: the squared residual a
    displacement per line explains, estimated from the two halves' independent readings of it (below); the item's
    sum of squared residuals; and per ``BINS`` line position bins, the sums of ``residual * g`` and ``g^2``.

    A line displaced by ``d`` has ``sum(r g) = -d G_a + noise`` in one half and ``-d G_b + noise`` in the other
    (``G`` the halves' ``sum(g^2)``), so ``2 rg_a rg_b / sqrt(G_a G_b)`` has the expectation ``2 d^2 sqrt(G_a G_b)``:
    the squared residual the displacement explains, ``d^2 (G_a + G_b)``, for halves of equal gradient, less for
    unequal ones, and 0 when the residual does not follow the gradient (the halves' noise is independent). It
    never exceeds the line's own sum of squared residuals (Cauchy-Schwarz), where a coefficient fitted on one half
    and scored on the other costs up to ``(rg_a / G_a)^2 G_b``, unbounded when ``G_a`` is small: on camsim's pixel
    slip one pair's such score was -0.69 of its residual (master seed 2885439120, at 11bf7c7), and the draw's share
    -0.005 with an interval of -0.36 to 0.35."""
    rg_a, gg_a, rg_b, gg_b, rr = terms.T
    explained = float(np.sum(2.0 * rg_a * rg_b / np.sqrt(np.maximum(gg_a * gg_b, 1e-300))))
    bins = np.arange(len(terms)) * BINS // len(terms)
    return np.concatenate(
        [
            [explained, rr.sum()],
            np.bincount(bins, weights=rg_a + rg_b, minlength=BINS),
            np.bincount(bins, weights=gg_a + gg_b, minlength=BINS),
        ]
    )


def displacement_tests(
    sample: ResidualSample, share_of_base: Callable[[float], float], rng: np.random.Generator
) -> list[dict]:
    """Frame pairs: are lines of the measured frame displaced from the predicted one? A line holding the predicted
    content moved ``d`` pixels along it reads ``predicted(x + d)`` where the model put ``predicted(x)``, so its
    residual (predicted - measured) is about ``-d g``, ``g`` the prediction's gradient along the line. Rows move
    along themselves when EMI drops pixel clocks (camsim's pixel slip: each corrupted row a few pixels early), in a
    rolling-shutter skew, or by a rotation about the centre (constant along each row, growing with its distance).

    Per frame and line, each half of the line reads ``d`` independently, and the statistic is the share of the
    residual's sum of squares that the two readings agree a displacement explains (``displacement_columns``; all
    lines, all items' totals). A residual that does not follow the gradient gives about 0, where one coefficient
    per line in sample explains about lines / values by chance, and more when neighbours correlate: 0.005-0.031 of
    the residual in 47 of camsim's 48 case runs without a displacement and 0.063 on one halo case, against 0.19 and
    0.41 of the pixel slip's and 0.17-0.18 of the rotation blur's; pooled over the frame, r squared on the slip was
    only 0.023 and 0.13, since the displaced rows move from frame to frame (docs/bench/session47/
    registration_probe.txt). It also found a displacement nobody meant to plant: camsim's blur null (master seed
    2885439120) had a share along columns of 0.030 (0.026-0.034), every pair displaced +0.03 to +0.10 px. camsim's
    paper path sampled both of its ends, a spread 4.3% wider than a constant-speed path's; with samples at step
    centres the share is 0.012, and the blur nulls of 10 master seeds report no structure, where 4 did
    (docs/bench/session47.md).

    No permutation null, hence no place in the family: structure remains when the share's item-bootstrap interval
    has its low end above ``MIN_EXPLAINED`` and the share times the residual's mean square is ``MIN_SHARE_OF_BASE``
    of the base error. ``where`` gives the displacement over all lines (``-sum(r g) / sum(g^2)``, pixels) and the
    line-position bin where it is largest."""
    tests = []
    for direction, per_item in sample.lines.items():
        columns = np.array([displacement_columns(terms) for terms in per_item])
        every_item = columns.sum(axis=0)
        totals = resummed_totals(columns, draws=RESUMMED_DRAWS, rng=rng)
        share = percentile_interval(
            float(every_item[0] / max(every_item[1], 1e-300)), totals[:, 0] / np.maximum(totals[:, 1], 1e-300)
        )
        rg, gg = every_item[2 : 2 + BINS], every_item[2 + BINS :]
        shift = percentile_interval(
            float(-rg.sum() / max(gg.sum(), 1e-300)),
            -totals[:, 2 : 2 + BINS].sum(axis=1) / np.maximum(totals[:, 2 + BINS :].sum(axis=1), 1e-300),
        )
        by_bin = np.where(gg > 0, -rg / np.maximum(gg, 1e-300), 0.0)
        worst = int(np.argmax(np.abs(by_bin)))
        line = direction.removesuffix("s")
        tests.append(
            {
                "variable": f"displacement_along_{direction}",
                "statistic": "share explained by a displacement per line, read in each half",
                "value": share.estimate,
                "interval": share.as_dict(),
                "share_of_base_mse": share_of_base(share.estimate),
                "displacement_px": shift.as_dict(),
                "significant": bool(
                    share.low > MIN_EXPLAINED and share_of_base(share.estimate) >= MIN_SHARE_OF_BASE
                ),
                "where": f"measured(x) ~ predicted(x + d) along each {line}: d {shift.estimate:+.2f} px over all "
                f"{direction} (90% interval {shift.low:+.2f} to {shift.high:+.2f}), largest {by_bin[worst]:+.2f} px "
                f"in the {direction} at {worst / BINS:.3g}-{(worst + 1) / BINS:.3g} of the frame",
            }
        )
    return tests


def neighbour_tests(
    sample: ResidualSample, share_of_base: Callable[[float], float], rng: np.random.Generator
) -> list[dict]:
    """Per kind of neighbour pairs: the correlation of the two residuals of a pair (smooth structure): ``LAG`` values
    apart along rows or columns of a frame, or as its ``pairing`` says (a table's nearest rows)."""
    tests = []
    for name, neighbours in sample.neighbours.items():
        columns = np.array([moment_columns(a, b) for a, b in neighbours.pairs])
        totals = resummed_totals(neighbours.resampled_columns(columns), draws=RESUMMED_DRAWS, rng=rng)
        r = percentile_interval(
            float(correlation_of_totals(columns.sum(axis=0, keepdims=True))[0]), correlation_of_totals(totals)
        )
        tests.append(
            {
                "variable": name,
                "statistic": "neighbour correlation" if neighbours.pairing else f"lag-{LAG} correlation",
                "value": r.estimate,
                "interval": r.as_dict(),
                "share_of_base_mse": share_of_base(r.estimate),
                "significant": bool(
                    r.low > MIN_NEIGHBOUR_CORR and share_of_base(r.estimate) >= MIN_SHARE_OF_BASE
                ),
                "where": agreeing_group(columns, neighbours.groups)
                if neighbours.groups is not None
                else f"neighbouring residuals {LAG} values apart along {name.split('_')[-1]}",
            }
        )
        if neighbours.pairing:
            tests[-1]["pairing"] = neighbours.pairing
    return tests


def agreeing_group(columns: np.ndarray, groups: list[str]) -> str:
    """The group whose pairs share the most residual: the largest mean product of a pair's two residuals, given as
    the root of it (the residual the two have in common), with the same figure over every pair (``columns``: each
    item's ``moment_columns``, ``groups`` its group)."""
    names, group = np.unique(np.asarray(groups, dtype=str), return_inverse=True)
    counts = np.bincount(group, weights=columns[:, 0], minlength=len(names))
    products = np.bincount(group, weights=columns[:, 5], minlength=len(names))
    if not counts.any():
        return "no pairs"
    shared = np.where(counts > 0, products / np.maximum(counts, 1.0), -np.inf)
    top = int(np.argmax(shared))
    overall = products.sum() / counts.sum()

    def root(x: float) -> str:
        return f"{math.copysign(math.sqrt(abs(x)), x):.3g}"

    return (
        f"the pairs share {root(overall)} (root mean product), most under {names[top]}: {root(shared[top])}"
    )


def item_errors(problem, fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(each item's RMSE, each item's sum of squared errors) of ``fit`` over ``items``."""
    squared, counts = problem.item_squared_errors(fit, items)
    squared = np.asarray(squared, np.float64)
    return np.sqrt(squared / np.maximum(np.asarray(counts, np.float64), 1.0)), squared


def outlying_item_tests(
    problem, fit, items: np.ndarray, fit_items: np.ndarray, share_of_base: Callable[[float], float]
) -> list[dict]:
    """Held-out items whose error exceeds ``OUTLIER_FACTOR`` x the largest fit item's, and their share of the
    held-out squared error (the module docstring's third test); [] with fewer than ``MIN_FIT_ITEMS`` fit items."""
    if len(fit_items) < MIN_FIT_ITEMS or len(items) == 0:
        return []
    reference = float(item_errors(problem, fit, np.asarray(fit_items))[0].max())
    errors, squared = item_errors(problem, fit, np.asarray(items))
    outlying = errors > OUTLIER_FACTOR * reference
    share = float(squared[outlying].sum() / max(squared.sum(), 1e-300))
    where = ", ".join(
        f"{problem.item_label(int(i))}: {e:.3g}"
        for i, e in sorted(zip(items[outlying], errors[outlying], strict=True), key=lambda t: -t[1])
    )
    return [
        {
            "variable": "items",
            "statistic": "outlying items' share of the squared error",
            "value": share,
            "outlying_items": [int(i) for i in items[outlying]],
            "largest_fit_item_error": reference,
            "share_of_base_mse": share_of_base(share),
            "significant": bool(share >= OUTLIER_SHARE and share_of_base(share) >= MIN_SHARE_OF_BASE),
            "where": f"{int(outlying.sum())} of {len(items)} held-out items err by over {OUTLIER_FACTOR:g}x the "
            f"largest fit item's error ({reference:.3g}): {where or 'none'}",
        }
    ]


def structure_summary(found: list[dict], residual: str = "held-out residual") -> str:
    if not found:
        return f"no structure left in the {residual} by the stated rule"

    def sentence(t: dict) -> str:
        if t["variable"] == "items":
            return (
                f"the model fails on a few items ({t['where']}; {100 * t['value']:.0f}% of the squared error)"
            )
        if t["statistic"] == "eta2 of the noise size excess":
            return (
                f"residual's variance beyond sensor noise depends on {t['variable'].removeprefix('variance_by_')} "
                f"(eta2 {t['value']:.3f}, 90% interval {t['interval']['low']:.3f}-{t['interval']['high']:.3f}; "
                f"{t['where']})"
            )
        if t["variable"].startswith("displacement_along_"):
            return (
                f"the {t['variable'].removeprefix('displacement_along_')} are displaced from the prediction (read in "
                f"each half of a line, a displacement per line explains {100 * t['value']:.1f}% of the residual, 90% "
                f"interval {100 * t['interval']['low']:.1f}-{100 * t['interval']['high']:.1f}%; {t['where']})"
            )
        if t["statistic"] == "eta2":
            return (
                f"residual depends on {t['variable']} (eta2 {t['value']:.3f}, 90% interval "
                f"{t['interval']['low']:.3f}-{t['interval']['high']:.3f}, r = {t['r']['estimate']:+.2f}; "
                f"{t['where']})"
            )
        if t["statistic"] == "neighbour correlation":
            return (
                f"neighbours err alike: {t['pairing']} correlate {t['value']:.3f} (90% interval "
                f"{t['interval']['low']:.3f}-{t['interval']['high']:.3f}; {t['where']})"
            )
        return (
            f"residual is smooth: {t['where']} ({t['statistic']} {t['value']:.3f}, 90% interval "
            f"{t['interval']['low']:.3f}-{t['interval']['high']:.3f})"
        )

    return "unexplained structure: " + "; ".join(sentence(t) for t in found)
