"""EM truncation frame pairs: a band of rows lost from the frame buffer, the tail repeated."""

from __future__ import annotations

import numpy as np
import torch
from scipy import integrate, optimize, special, stats

from lerobot_phantom.calibration.core import Effect, Fit, Param
from lerobot_phantom.calibration.frame_models.common import LatentFrameProblem, Pair
from lerobot_phantom.transforms.em_truncation import paper_band_start, rows_after_losing

# agreeing_counts_jitter's grids: the log jitter from a tenth of a row to the bound, the slope across one frame
JITTER_GRID_POINTS = 48
SLOPE_GRID_POINTS = 161

TRUNCATION_EFFECTS = (
    Effect(
        "free_band_position",
        "the interference corrupts the frame-buffer address at a moment set by the attacker's signal timing, not "
        "by how many rows are lost: the deleted band starts anywhere in the frame instead of at int(h * r)",
    ),
)


def count_law(counts: np.ndarray, heights: np.ndarray, intensities: np.ndarray) -> tuple[float, float, float]:
    """The line ``r = a s`` from attack intensity ``s`` to truncation ratio, read from frames that lost
    ``counts`` rows: (lowest slope, highest slope, jitter).

    The count is ``int(h r)``, a floor (the paper's Appendix A, and ``transforms.em_truncation``): a frame that
    lost ``n`` of ``h`` rows had ``r`` anywhere in ``[n / h, (n + 1) / h)``, and one line explains every fit frame
    when the slopes those intervals allow overlap; each slope in the overlap is then as likely as any other, and a
    frame's ratio is predicted uniform over ``[s low, s high]``, plus the jitter such agreement leaves possible
    (:func:`agreeing_counts_jitter`). Where they do not overlap (the interference's timing varies from frame to
    frame, or a frame was registered wrongly), the ratio jitters, ``r = a s + e`` with ``e`` normal of standard
    deviation ``d``, and the line and jitter are the most likely ones (:func:`most_likely_jitter`): one slope. A
    least-squares line through the counts (``n / h``, rounded back, until session 59) sits half a row low and has
    no spread of its own: a frame beyond the fit frames' intensities was predicted a row short, every row below its
    band wrong, and a free band start looked like a gain on a null draw."""
    low, high = counts / heights, (counts + 1) / heights
    lit = intensities > 0
    touching = least_jitter(low, high, intensities)
    if touching == 0.0:
        if not lit.any():
            return 0.0, 0.0, 0.0
        lowest = max(0.0, float(np.max(low[lit] / intensities[lit])))
        highest = max(lowest, float(np.min(high[lit] / intensities[lit])))
        return lowest, highest, agreeing_counts_jitter(counts[lit], heights[lit], intensities[lit])
    slope, jitter = most_likely_jitter(low, high, intensities, touching)
    return slope, slope, jitter


def least_jitter(low: np.ndarray, high: np.ndarray, intensities: np.ndarray) -> float:
    """The least ``d`` for which some line ``a s`` (``a >= 0``) comes within ``d`` of every frame's interval
    ``[low, high]``: the slope intervals of frames ``i`` and ``j`` meet once ``d >= (low_i s_j - high_j s_i) /
    (s_i + s_j)``, and a frame at zero intensity allows no slope to move it, only jitter (``d >= low_i``)."""
    pairwise = np.add.outer(intensities, intensities)
    needed = np.outer(low, intensities) - np.outer(intensities, high)
    return max(
        0.0,
        float(np.max(needed[pairwise > 0] / pairwise[pairwise > 0], initial=0.0)),
        float(np.max(low[intensities <= 0], initial=0.0)),
    )


def log_interval_probability(
    low: np.ndarray, high: np.ndarray, centre: np.ndarray, jitter: float
) -> np.ndarray:
    """``log P(low <= centre + e < high)`` for ``e`` normal with standard deviation ``jitter`` (scipy's
    two-argument ``logcdf``, accurate in both tails; real, as every interval here has a probability)."""
    return np.real(stats.Normal(mu=centre, sigma=jitter).logcdf(low, high))


def most_likely_jitter(
    low: np.ndarray, high: np.ndarray, intensities: np.ndarray, touching: float
) -> tuple[float, float]:
    """The slope ``a`` and normal jitter ``d`` under which the frames' counts are most likely (each frame's the
    probability that ``a s + e`` falls in its interval ``[low, high)``: interval-censored normal regression),
    where the intervals do not meet (``touching`` = :func:`least_jitter` > 0).

    Session 61 tried the least uniform jitter first, then the most likely uniform one: at the least, the line only
    touches the outermost intervals, whose counts then have no probability at all (two frames at one intensity
    that lost 10 and 12 rows predicted 11 for every frame); a uniform, even at its most likely width, still gives a
    held-out frame no probability one row past the fit frames' spread, which a free band start then "explained"
    on null draws whose count varied from frame to frame. A normal jitter gives every count a probability that
    falls with its distance from the line. Starts at the touching line, ``d`` at the touching jitter."""
    lit = intensities > 0
    slope = 0.0
    if lit.any():
        slope = 0.5 * (
            max(0.0, float(np.max((low[lit] - touching) / intensities[lit])))
            + float(np.min((high[lit] + touching) / intensities[lit]))
        )

    def negative_log_likelihood(x: np.ndarray) -> float:
        return -float(np.sum(log_interval_probability(low, high, x[0] * intensities, float(np.exp(x[1])))))

    result = optimize.minimize(
        negative_log_likelihood,
        np.array([slope, np.log(touching)]),
        method="L-BFGS-B",
        # the transform's and Param's range: a ratio past 0.5 would lose more rows than the tail can repeat
        bounds=[(0.0, 0.5), (np.log(touching) - 5.0, np.log(0.5))],
    )
    return float(result.x[0]), float(np.exp(result.x[1]))


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
    bounds are in (so a probability far from the centre is not the difference of two numbers near 1). For the
    posterior's grids, tens of thousands of values per fit: about 11 times faster than
    :func:`log_interval_probability`, whose log stays exact where this underflows to 0 (38 deviations out), which
    the most likely jitter's optimiser needs and a grid weight does not."""
    x, y = (below - centre) / jitter, (above - centre) / jitter
    return np.where(x > 0, special.ndtr(-x) - special.ndtr(-y), special.ndtr(y) - special.ndtr(x))


def agreeing_counts_jitter(counts: np.ndarray, heights: np.ndarray, intensities: np.ndarray) -> float:
    """The jitter frames whose counts one line explains leave possible: the posterior median of ``d`` (``r = a
    s + e``, ``e`` normal, standard deviation ``d``), flat prior on the slope over ``[0, 0.5]`` and a log-uniform one
    on ``d`` (its scale is unknown) from a tenth of a row of the tallest frame, below which no count tells it from
    none, to 0.5, the transform's bound.

    Agreement is no proof of no jitter: four frames whose counts jitter by a couple of rows agree with one line
    often enough, and the uniform slope range alone (session 59's law, a jitter of 0 until session 62) gives a
    held-out frame one row past it no probability at all, which a free band start then "explained" on a null draw
    (camsim count-spread seed 596587659). The likelihood stays near its top for every ``d`` up to the slack the
    agreeing intervals leave and then falls as ``d ** -(n - 1)`` for ``n`` frames (the slope takes one), so the
    posterior narrows with more frames. The median, not the mean: with three or fewer frames that tail leaves the
    mean at the prior's bound. The slope is integrated on a grid that spans the frame at the highest intensity's
    interval and six jitters either side of it (outside, that frame alone is less likely than 1e-9)."""
    if len(counts) == 0:
        return 0.0
    below, above = count_intervals(counts, heights, heights // 2)
    jitters = np.geomspace(0.1 / heights.max(), 0.5, JITTER_GRID_POINTS)
    top = int(np.argmax(intensities))
    reach = 6.0 * jitters
    first = np.clip((np.nan_to_num(below[top], neginf=0.0) - reach) / intensities[top], 0.0, 0.5)
    last = np.clip((np.nan_to_num(above[top], posinf=0.5) + reach) / intensities[top], 0.0, 0.5)
    slopes = np.linspace(first, last, SLOPE_GRID_POINTS)  # (slopes, jitters)
    probability = interval_probability(
        below, above, slopes[..., None] * intensities, jitters[None, :, None]
    ).prod(axis=-1)
    likelihood = np.trapezoid(probability, slopes, axis=0)  # the slope's flat prior, integrated out
    # the log-uniform prior: the posterior is the likelihood over log d
    cumulative = integrate.cumulative_trapezoid(likelihood, np.log(jitters), initial=0.0)
    return float(np.exp(np.interp(0.5 * cumulative[-1], cumulative, np.log(jitters))))


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
            weights = np.exp(log_interval_probability(below, above, np.full(len(counts), low), jitter))
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
        """Rows lost the fitted model expects for pair ``index`` and their probabilities (:func:`count_law`)."""
        pair = self.pairs[index]
        low, high = fit.extra["slope_range"]
        jitter = fit.params["ratio_jitter"]
        return count_probabilities(
            pair.intensity * low, pair.intensity * high, pair.height, pair.height // 2, jitter
        )

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
        low, high, jitter = count_law(np.asarray(counts), np.asarray(heights), np.asarray(strengths))
        fit = Fit(
            effects,
            {"ratio_per_intensity": 0.5 * (low + high), "ratio_jitter": jitter},
            {"slope_range": [low, high]},
        )
        fit.extra["noise_variance"] = self.noise_variance(fit, items)
        return fit

    def transform_kwargs(self, fit: Fit) -> dict:
        """``EMTruncation`` options: the measured line from intensity to ratio in place of the paper's level table
        (the middle of the slopes the fit frames allow), and the band's start drawn anywhere where the written
        model frees it; each frame's ratio is drawn from the law held-out frames are predicted with (half the
        slopes' range as the spread, and the jitter)."""
        low, high = fit.extra["slope_range"]
        return {
            "ratio_per_intensity": fit.params["ratio_per_intensity"],
            "ratio_per_intensity_spread": 0.5 * (high - low),
            "ratio_jitter": fit.params["ratio_jitter"],
            "free_band_position": "free_band_position" in fit.effects,
        }

    def derived(self, fit: Fit) -> dict:
        return {"ratio_at_intensity_1": fit.params["ratio_per_intensity"]}
