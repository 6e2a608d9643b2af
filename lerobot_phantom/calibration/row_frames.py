"""Frame pairs for the row-structured attacks: EM truncation and the laser color strip.

Both attacks act on whole sensor rows, and where in the frame they act is set by timing the attacker does not
report (when the interference hits the frame buffer, the laser's pulse phase). As for the EM color strip, that
placement is estimated from each frame itself, also for held-out frames; the fitted parameters are what the
frames share (colour gains, stripe geometry).
"""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit
from lerobot_phantom.calibration.frames import FrameProblem, Pair

# ---------------------------------------------------------------------------------------------------------------
# EM truncation

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


class TruncationFrames(FrameProblem):
    """Which rows were lost is read from each frame by an exhaustive search over integer row counts (and, with
    ``free_band_position``, band starts): the squared error of every (output row, source row) match is computed
    once per pair, so the search is exact and costs no fitting."""

    attack = "em_truncation"
    base_model = (
        "rows [int(h r), 2 int(h r)) deleted and the last int(h r) rows appended (the paper's EM truncation; the "
        "ratio r read from each frame by a search over integer row counts)"
    )
    extended_model = "EM truncation with a free band position"
    candidates = TRUNCATION_EFFECTS

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        self._placements: dict[tuple[bool, int], tuple[int, int]] = {}

    @staticmethod
    def match_costs(pair: Pair) -> np.ndarray:
        """``costs[i, j]``: squared error of predicting attacked row ``i`` by clean row ``j``."""
        attacked = pair.attacked.permute(1, 0, 2).reshape(pair.height, -1)
        clean = pair.clean.permute(1, 0, 2).reshape(pair.height, -1)
        return (torch.cdist(attacked, clean) ** 2).numpy()

    def placement(self, free_start: bool, index: int) -> tuple[int, int]:
        """(rows lost, band start) that best explain pair ``index``."""
        key = (free_start, index)
        if key not in self._placements:
            costs = self.match_costs(self.pairs[index])
            height = len(costs)
            rows = np.arange(height)
            same = np.concatenate([[0.0], np.cumsum(np.diag(costs))])  # rows kept in place
            best = (float(same[-1]), 0, 0)  # nothing lost
            for num in range(1, height // 2 + 1):
                moved = np.concatenate(
                    [[0.0], np.cumsum(costs[rows[: height - num], rows[: height - num] + num])]
                )
                starts = (
                    np.arange(0, height - 2 * num + 1) if free_start else np.array([paper_start(height, num)])
                )
                # rows < start stay, rows [start, h - num) move up by num, the last num rows repeat the tail
                total = same[starts] + (moved[height - num] - moved[starts]) + (same[-1] - same[height - num])
                k = int(np.argmin(total))
                if total[k] < best[0]:
                    best = (float(total[k]), num, int(starts[k]))
            self._placements[key] = (best[1], best[2])
        return self._placements[key]

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        num, start = self.placement("free_band_position" in fit.effects, index)
        pair = self.pairs[index]
        return pair.clean[:, torch.as_tensor(truncation_source_rows(pair.height, num, start))]

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        free = "free_band_position" in effects
        ratios, starts, strengths = [], [], []
        for i in items:
            num, band_start = self.placement(free, int(i))
            ratios.append(num / self.pairs[int(i)].height)
            starts.append(band_start / self.pairs[int(i)].height)
            strengths.append(self.pairs[int(i)].intensity)
        s, r = np.asarray(strengths), np.asarray(ratios)
        # the shared part: the ratio per unit of attack intensity (least squares through the origin)
        params = {
            "ratio_per_intensity": float((s * r).sum() / max((s * s).sum(), 1e-12)),
            "mean_ratio": float(r.mean()),
        }
        if free:
            params["mean_band_start_share"] = float(np.mean(starts))
        return Fit(effects, params)

    def transform_kwargs(self, fit: Fit) -> dict:
        """``EMTruncation`` keeps its intensity -> ratio table; a free band position is reported, not simulated."""
        return {}

    def derived(self, fit: Fit) -> dict:
        return {"ratio_at_intensity_1": fit.params["ratio_per_intensity"]}


ROW_FRAME_PROBLEMS = {"em_truncation": TruncationFrames}
