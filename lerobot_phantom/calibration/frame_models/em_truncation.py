"""EM truncation frame pairs: a band of rows lost from the frame buffer, the tail repeated."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from scipy import integrate, special

from lerobot_phantom.calibration.core import Effect, Fit, Param
from lerobot_phantom.calibration.frame_models.common import LatentFrameProblem, Pair
from lerobot_phantom.transforms.em_truncation import MAX_RATIO, paper_band_start, rows_after_losing

# posterior_law's grids: the log jitter from a tenth of a row to the bound (96 points put the median and eighths
# within 0.4% of a 1536-point grid's, 48 within 1.7%: docs/bench/session63/law_choices.txt), the slope across one
# frame
JITTER_GRID_POINTS = 96
SLOPE_GRID_POINTS = 161
# equally likely jitters the law predicts with and the calibrated transform draws from: the posterior's
# (k + 1/2) / 8 quantiles (on session 63's recovery draws 4, 8 and 16 gave mean held-out log probabilities within
# 0.009 of each other, and the median alone left a held-out count without probability in two settings of five:
# docs/bench/session63/law_choices.txt)
JITTER_QUANTILES = 8

TRUNCATION_EFFECTS = (
    Effect(
        "free_band_position",
        "the interference corrupts the frame-buffer address at a moment set by the attacker's signal timing, not "
        "by how many rows are lost: the deleted band starts anywhere in the frame instead of at int(h * r)",
    ),
)


@dataclass(frozen=True)
class CountLaw:
    """How many rows a frame loses at intensity ``s``: ``int(h r)`` with ``r = a s + e``, ``a`` uniform on
    ``[lowest, highest]``, ``e`` normal with standard deviation drawn from ``jitters`` (equally likely); ``jitter``
    is their posterior median, the figure reported."""

    lowest: float
    highest: float
    jitter: float
    jitters: tuple[float, ...]


def count_law(counts: np.ndarray, heights: np.ndarray, intensities: np.ndarray) -> CountLaw:
    """The line ``r = a s`` from attack intensity ``s`` to truncation ratio, read from frames that lost
    ``counts`` rows.

    The count is ``int(h r)``, a floor (the paper's Appendix A, and ``transforms.em_truncation``): a frame that
    lost ``n`` of ``h`` rows had ``r`` anywhere in ``[n / h, (n + 1) / h)`` (:func:`count_intervals`). The ratio
    jitters from frame to frame, ``r = a s + e`` with ``e`` normal of standard deviation ``d`` (the interference's
    timing varies), and ``a`` and ``d`` are read from their posterior (:func:`posterior_law`); a frame is predicted
    with ``d``'s posterior quantiles, not one value of it, so ten frames that happen to lie close to the line do not
    rule out an eleventh three rows off (with the median alone, 5 of 1000 draws of ten frames from the transform's
    own law gave a held-out count no probability; session 63). Where one line explains every fit frame (the slopes
    the intervals allow overlap), each slope in the overlap is as likely as any other and a frame's ratio is
    predicted uniform over ``[s low, s high]`` plus the jitter; where none does, one slope. Frames at zero
    intensity carry no evidence: the transform never truncates them. A least-squares line through the counts (``n /
    h``, rounded back, until session 59) sat half a row low and had no spread of its own; the most likely jitter
    (sessions 61-62, where counts contradict one line) underestimated it on draws from the transform's own law and
    gave a held-out count a row or two past the fit frames' no probability (session 63)."""
    lit = intensities > 0
    counts, heights, intensities = counts[lit], heights[lit], intensities[lit]
    if len(counts) == 0:
        return CountLaw(0.0, 0.0, 0.0, (0.0,))
    below, above = count_intervals(counts, heights, heights // 2)
    slope, jitter, jitters = posterior_law(below, above, int(heights.max()), intensities)
    lowest = max(0.0, float(np.max(below / intensities)))
    # a frame that lost half its rows at intensity 0.6 needs a slope past the transform's bound (intensities reach 1,
    # so the slope's bound is the ratio's): no line explains it
    if least_jitter(below, above, intensities) > 0.0 or lowest > MAX_RATIO:
        return CountLaw(slope, slope, jitter, jitters)
    return CountLaw(lowest, min(MAX_RATIO, max(lowest, float(np.min(above / intensities)))), jitter, jitters)


def least_jitter(below: np.ndarray, above: np.ndarray, intensities: np.ndarray) -> float:
    """The least ``d`` for which some line ``a s`` (``a >= 0``) comes within ``d`` of every (lit) frame's interval
    ``[below, above)``: the slope intervals of frames ``i`` and ``j`` meet once ``d >= (below_i s_j - above_j s_i)
    / (s_i + s_j)``."""
    needed = np.outer(below, intensities) - np.outer(intensities, above)
    return max(0.0, float(np.max(needed / np.add.outer(intensities, intensities))))


def count_intervals(counts: np.ndarray, height: np.ndarray | int, most: np.ndarray | int):
    """The ratios ``[below, above)`` that give each count once ``int(h r)`` is clipped to ``[0, most]``: a ratio
    the jitter takes below 0 still loses no rows, and one past the top loses ``most``."""
    below = np.where(counts == 0, -np.inf, counts / height)
    above = np.where(counts >= most, np.inf, (counts + 1) / height)
    return below, above


def interval_probability(
    below: np.ndarray, above: np.ndarray, centre: np.ndarray, jitter: np.ndarray
) -> np.ndarray:
    """``P(below <= centre + e < above)`` for ``e`` normal with standard deviation ``jitter``, from the tail both
    bounds are in (so a probability far from the centre is not the difference of two numbers near 1; it
    underflows to 0 only 38 deviations out). For the posterior's grids, over a hundred thousand values per fit:
    18 times faster than scipy's ``stats.Normal(...).logcdf(below, above)`` on 161 x 96 x 8 (5.4 ms against 96.0
    ms, docs/bench/session63/law_choices.txt)."""
    x, y = (below - centre) / jitter, (above - centre) / jitter
    return np.where(x > 0, special.ndtr(-x) - special.ndtr(-y), special.ndtr(y) - special.ndtr(x))


def posterior_law(
    below: np.ndarray, above: np.ndarray, tallest: int, intensities: np.ndarray
) -> tuple[float, float, tuple[float, ...]]:
    """The posterior mean of the slope ``a``, and the median and ``(k + 1/2) / JITTER_QUANTILES`` quantiles of the
    jitter ``d`` (``r = a s + e``, ``e`` normal, standard deviation ``d``), given lit frames whose ratios lay in
    ``[below, above)``: flat prior on the slope over ``[0, 0.5]`` and a log-uniform one on ``d`` (its scale is
    unknown) from a tenth of a row of the ``tallest`` frame, below which no count tells it from none, to 0.5, the
    transform's bound.

    Neither no jitter where counts agree nor the most likely one where they contradict: agreement is no proof of no
    jitter (four frames whose counts jitter by a couple of rows agree with one line often enough, and a held-out
    frame one row past the slopes' range then had no probability: camsim count-spread seed 596587659 named a free
    band for it; session 62), and the most likely ``d`` of ten frames fell below the truth, the slope being fitted
    on the same counts (0.90 rows for 1 on draws of the transform's own law; session 63); with the slope integrated
    out, the median's median over draws is within 6% of the truth in each of that study's eight settings. The
    likelihood stays near its top for every ``d`` up to the slack the intervals leave and then falls as ``d ** -(n
    - 1)`` for ``n`` frames, so the posterior narrows with more frames; with three or fewer that tail
    leaves the mean at the prior's bound, hence the median. The slope is integrated on a grid spanning the frame at
    the highest intensity's interval and six jitters either side (outside, that frame alone is less likely than
    1e-9)."""
    jitters = np.geomspace(0.1 / tallest, MAX_RATIO, JITTER_GRID_POINTS)
    top = int(np.argmax(intensities))
    reach = 6.0 * jitters
    first = np.clip((np.nan_to_num(below[top], neginf=0.0) - reach) / intensities[top], 0.0, MAX_RATIO)
    last = np.clip((np.nan_to_num(above[top], posinf=MAX_RATIO) + reach) / intensities[top], 0.0, MAX_RATIO)
    slopes = np.linspace(first, last, SLOPE_GRID_POINTS)  # (slopes, jitters)
    probability = interval_probability(
        below, above, slopes[..., None] * intensities, jitters[None, :, None]
    ).prod(axis=-1)
    likelihood = np.trapezoid(probability, slopes, axis=0)  # the slope's flat prior, integrated out
    # the log-uniform prior: the posterior is the likelihood over log d
    cumulative = integrate.cumulative_trapezoid(likelihood, np.log(jitters), initial=0.0)
    shares = np.concatenate([[0.5], (np.arange(JITTER_QUANTILES) + 0.5) / JITTER_QUANTILES])
    quantiles = np.exp(np.interp(shares * cumulative[-1], cumulative, np.log(jitters)))
    slope_moment = np.trapezoid(np.trapezoid(probability * slopes, slopes, axis=0), np.log(jitters))
    return float(slope_moment / cumulative[-1]), float(quantiles[0]), tuple(map(float, quantiles[1:]))


def count_probabilities(
    low: float, high: float, height: int, most: int, jitter: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Rows lost, ``int(h r)`` clipped to ``[0, most]``, and their probabilities, for a ratio uniform on
    ``[low, high]``, with ``jitter`` plus a normal of that standard deviation (counts below a millionth of a percent
    left out).

    Uniform plus normal: the probability of ``[b, c)`` is the mean over ``r`` in ``[low, high]`` of ``Phi((c - r)
    / d) - Phi((b - r) / d)``, and ``x Phi(x) + phi(x)`` is the antiderivative of ``Phi``."""
    if jitter > 0:
        counts = np.arange(0, most + 1)
        below, above = count_intervals(counts, height, most)
        if high - low > 1e-12:
            weights = np.clip(
                smeared_mass(above, low, high, jitter) - smeared_mass(below, low, high, jitter), 0.0, None
            )
        else:
            weights = interval_probability(below, above, np.full(len(counts), low), jitter)
        keep = weights > 1e-8
        return counts[keep], weights[keep] / weights[keep].sum()
    first, last = int(np.floor(low * height)), int(np.floor(high * height))
    counts = np.arange(first, last + 1)
    if high - low > 1e-12:
        overlap = np.minimum((counts + 1) / height, high) - np.maximum(counts / height, low)
        weights = np.clip(overlap, 0.0, None)
    else:
        counts, weights = counts[:1], np.ones(1)
    counts, where = np.unique(np.clip(counts, 0, most), return_inverse=True)
    merged = np.bincount(where, weights=weights, minlength=len(counts))
    keep = merged > 0
    return counts[keep], merged[keep] / merged[keep].sum()


def smeared_mass(bound: np.ndarray, low: float, high: float, jitter: float) -> np.ndarray:
    """``P(r + e < bound)`` for ``r`` uniform on ``[low, high]`` and ``e`` normal with standard deviation
    ``jitter`` (0 at ``-inf``, 1 at ``+inf``)."""

    def antiderivative(x: np.ndarray) -> np.ndarray:
        return x * special.ndtr(x) + np.exp(-0.5 * x**2) / np.sqrt(2 * np.pi)

    finite = np.isfinite(bound)
    inner = np.where(finite, bound, 0.0)
    mass = (
        jitter
        * (antiderivative((inner - low) / jitter) - antiderivative((inner - high) / jitter))
        / (high - low)
    )
    return np.where(finite, mass, (bound > 0).astype(float))


class TruncationFrames(LatentFrameProblem):
    """The fitted model predicts how many rows a frame loses from its intensity (:func:`count_law`); where the
    band starts is the paper's ``int(h r)``, or with ``free_band_position`` unknowable in advance (uniform over
    every possible start, :meth:`starts`). Fit frames are registered by an exhaustive search over row counts and
    starts (the squared error of every (output row, source row) match is computed once per pair); held-out frames
    are scored with the latent marginalised (``LatentFrameProblem``)."""

    attack = "em_truncation"
    base_model = (
        "rows [int(h r), 2 int(h r)) deleted and the last int(h r) rows appended (the paper's EM truncation; the "
        "ratio r predicted from the attack intensity by a fitted line)"
    )
    extended_model = "EM truncation with a free band position"
    candidates = TRUNCATION_EFFECTS
    latent = "rows lost and band start of each frame (timing of the interference)"

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        self._costs: dict[int, np.ndarray] = {}
        self._placements: dict[tuple[bool, int], tuple[int, int]] = {}

    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        return [Param("ratio_per_intensity", 0.2, 0.0, 0.5), Param("ratio_jitter", 0.0, 0.0, 0.5)]

    def match_costs(self, index: int) -> np.ndarray:
        """``costs[i, j]``: squared error of predicting attacked row ``i`` by clean row ``j`` (cached)."""
        if index not in self._costs:
            pair = self.pairs[index]
            attacked = pair.attacked.permute(1, 0, 2).reshape(pair.height, -1)
            clean = pair.clean.permute(1, 0, 2).reshape(pair.height, -1)
            self._costs[index] = (torch.cdist(attacked, clean) ** 2).numpy()
        return self._costs[index]

    def band_costs(self, index: int, num: int, starts: np.ndarray) -> np.ndarray:
        """SSE of pair ``index`` when ``num`` rows from each of ``starts`` are lost (the tail repeated)."""
        costs = self.match_costs(index)
        height = len(costs)
        rows = np.arange(height)
        same = np.concatenate([[0.0], np.cumsum(np.diag(costs))])  # rows kept in place
        if num == 0:
            return np.full(len(starts), same[-1])
        moved = np.concatenate([[0.0], np.cumsum(costs[rows[: height - num], rows[: height - num] + num])])
        # rows < start stay, rows [start, h - num) move up by num, the last num rows repeat the tail
        return same[starts] + (moved[height - num] - moved[starts]) + (same[-1] - same[height - num])

    def starts(self, free: bool, height: int, num: int) -> np.ndarray:
        """Where a band of ``num`` rows can start: the paper's row, or with a free position any row from the top
        to ``h - num``, the band then reaching into the rows the tail repeats (at ``h - num`` it is the tail
        itself and the frame comes out as it went in). Until session 59 a free band stopped at ``h - 2 num``,
        the paper's clamp, and ``num`` of the ``h - num + 1`` starts an independent simulator draws from (camsim:
        about a fifth at its typical counts) had no placement."""
        return (
            np.arange(0, height - num + 1) if free else paper_band_start(height, torch.tensor([num])).numpy()
        )

    def placement(self, free: bool, index: int) -> tuple[int, int]:
        """(rows lost, band start) that best explain pair ``index`` (registration: fit frames, or reporting)."""
        key = (free, index)
        if key not in self._placements:
            height = self.pairs[index].height
            best = (np.inf, 0, 0)
            for num in range(0, height // 2 + 1):
                starts = self.starts(free, height, num)
                total = self.band_costs(index, num, starts)
                k = int(np.argmin(total))
                if total[k] < best[0]:
                    best = (float(total[k]), num, int(starts[k]))
            self._placements[key] = (best[1], best[2])
        return self._placements[key]

    def predicted_counts(self, fit: Fit, index: int) -> tuple[np.ndarray, np.ndarray]:
        """Rows lost the fitted model expects for pair ``index`` and their probabilities (:class:`CountLaw`: the
        mean of the laws at each of the equally likely jitters)."""
        pair = self.pairs[index]
        low, high = fit.extra["slope_range"]
        most = pair.height // 2
        # the transform never truncates an unattacked frame, jitter or not
        jitters = fit.extra["jitters"] if pair.intensity > 0 else [0.0]
        mixture = np.zeros(most + 1)
        for jitter in jitters:
            counts, weights = count_probabilities(
                pair.intensity * low, pair.intensity * high, pair.height, most, jitter
            )
            mixture[counts] += weights / len(jitters)
        counts = np.flatnonzero(mixture)
        return counts, mixture[counts]

    def latent_candidates(self, fit: Fit, index: int) -> tuple[np.ndarray, np.ndarray]:
        free = "free_band_position" in fit.effects
        height = self.pairs[index].height
        counts, weights = self.predicted_counts(fit, index)
        sse, prior = [], []
        for num, weight in zip(counts, weights, strict=True):
            starts = self.starts(free, height, int(num))
            sse.append(self.band_costs(index, int(num), starts))
            prior.append(np.full(len(starts), weight / len(starts)))
        return np.concatenate(sse), np.concatenate(prior)

    def registered_sse(self, fit: Fit, index: int) -> float:
        num, start = self.placement("free_band_position" in fit.effects, index)
        return float(self.band_costs(index, num, np.array([start]))[0])

    def predict_registered(self, fit: Fit, index: int) -> torch.Tensor:
        num, start = self.placement("free_band_position" in fit.effects, index)
        pair = self.pairs[index]
        return pair.clean[:, rows_after_losing(pair.height, torch.tensor([num]), torch.tensor([start]))[0]]

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        free = "free_band_position" in effects
        counts, heights, strengths = [], [], []
        for i in items:
            num, band_start = self.placement(free, int(i))
            height = self.pairs[int(i)].height
            if free and (num == 0 or band_start + num >= height):
                continue  # an unchanged frame: the band may have been the tail itself, of any size
            counts.append(num)
            heights.append(height)
            strengths.append(self.pairs[int(i)].intensity)
        law = count_law(np.asarray(counts), np.asarray(heights), np.asarray(strengths))
        fit = Fit(
            effects,
            {"ratio_per_intensity": 0.5 * (law.lowest + law.highest), "ratio_jitter": law.jitter},
            {"slope_range": [law.lowest, law.highest], "jitters": list(law.jitters)},
        )
        fit.extra["noise_variance"] = self.noise_variance(fit, items)
        return fit

    def transform_kwargs(self, fit: Fit) -> dict:
        """``EMTruncation`` options: the measured line from intensity to ratio in place of the paper's level table
        (the middle of the slopes the fit frames allow), and the band's start drawn anywhere where the written
        model frees it; each frame's ratio is drawn from the law held-out frames are predicted with (half the
        slopes' range as the spread, and the equally likely jitters)."""
        low, high = fit.extra["slope_range"]
        return {
            "ratio_per_intensity": fit.params["ratio_per_intensity"],
            "ratio_per_intensity_spread": 0.5 * (high - low),
            "ratio_jitter": list(fit.extra["jitters"]),
            "free_band_position": "free_band_position" in fit.effects,
        }

    def derived(self, fit: Fit) -> dict:
        return {"ratio_at_intensity_1": fit.params["ratio_per_intensity"]}
