"""EM truncation frame pairs: a band of rows lost from the frame buffer, the tail repeated."""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param
from lerobot_phantom.calibration.frame_models.common import LatentFrameProblem, Pair

TRUNCATION_EFFECTS = (
    Effect(
        "free_band_position",
        "the interference corrupts the frame-buffer address at a moment set by the attacker's signal timing, not "
        "by how many rows are lost: the deleted band starts anywhere in the frame instead of at int(h * r)",
    ),
)


def truncation_source_rows(height: int, num: int, start: int) -> np.ndarray:
    """Source row of every output row when rows ``[start, start + num)`` are deleted and the tail is repeated."""
    rows = np.arange(height)
    shifted = (rows >= start) & (rows < height - num)
    return np.where(shifted, rows + num, rows)


def paper_start(height: int, num: int) -> int:
    """The paper's band start ``int(h r) = num``, clamped so the band never overlaps the appended tail (as
    ``transforms.em_truncation``)."""
    return max(0, min(num, height - 2 * num))


def count_law(counts: np.ndarray, heights: np.ndarray, intensities: np.ndarray) -> tuple[float, float, float]:
    """The line ``r = a s`` from attack intensity ``s`` to truncation ratio, read from frames that lost
    ``counts`` rows: (lowest slope, highest slope, jitter).

    The count is ``int(h r)``, a floor (the paper's Appendix A, and ``transforms.em_truncation``): a frame that
    lost ``n`` of ``h`` rows had ``r`` anywhere in ``[n / h, (n + 1) / h)``, and one line explains every fit frame
    when the slopes those intervals allow overlap; each slope in the overlap is then as likely as any other.
    Where they do not overlap (the interference's timing varies from frame to frame, or a frame was registered
    wrongly), the ratio is given the least jitter ``d`` that makes them overlap, ``r = a s + e`` with ``|e| <= d``,
    and the overlap is then one slope. Either way a frame's ratio is predicted uniform over
    ``[s low - d, s high + d]``. A least-squares line through the counts (``n / h``, rounded back, until session
    59) sits half a row low and has no spread of its own: a frame beyond the fit frames' intensities was predicted a
    row short, every row below its band wrong, and a free band start looked like a gain on a null draw."""
    low, high = counts / heights, (counts + 1) / heights
    lit = intensities > 0
    # the slope intervals of frames i and j overlap once d >= (low_i s_j - high_j s_i) / (s_i + s_j); a frame
    # at zero intensity allows no slope to move it, only jitter (d >= low_i)
    pairwise = np.add.outer(intensities, intensities)
    needed = np.outer(low, intensities) - np.outer(intensities, high)
    jitter = max(
        0.0,
        float(np.max(needed[pairwise > 0] / pairwise[pairwise > 0], initial=0.0)),
        float(np.max(low[~lit], initial=0.0)),
    )
    if not lit.any():
        return 0.0, 0.0, jitter
    lowest = max(0.0, float(np.max((low[lit] - jitter) / intensities[lit])))
    highest = float(np.min((high[lit] + jitter) / intensities[lit]))
    return lowest, max(lowest, highest), jitter


def count_probabilities(low: float, high: float, height: int, most: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows lost, ``int(h r)`` clipped to ``[0, most]``, and their probabilities, for a ratio uniform on
    ``[low, high]``."""
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
        return np.arange(0, height - num + 1) if free else np.array([paper_start(height, num)])

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
            pair.intensity * low - jitter, pair.intensity * high + jitter, pair.height, pair.height // 2
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
        return pair.clean[:, torch.as_tensor(truncation_source_rows(pair.height, num, start))]

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
        model frees it. The count's jitter is not simulated (``transforms.em_truncation``)."""
        return {
            "ratio_per_intensity": fit.params["ratio_per_intensity"],
            "free_band_position": "free_band_position" in fit.effects,
        }

    def derived(self, fit: Fit) -> dict:
        return {"ratio_at_intensity_1": fit.params["ratio_per_intensity"]}
