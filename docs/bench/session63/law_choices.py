"""The count law's design choices and costs, measured in one run (session 63):

``PYTHONPATH=. python docs/bench/session63/law_choices.py`` (from the repository root) prints

1. the mean held-out log probability per frame on ``count_law_recovery.py``'s design draws with 1 (the median
   alone), 4, 8 and 16 equally likely jitters (``JITTER_QUANTILES``, set on the module for the run);
2. how far the median and eighths of the jitter move with the log-jitter grid (``JITTER_GRID_POINTS`` 48 and 96)
   from a 1536-point grid, on the five count sets of ``test_the_law_is_the_posterior_by_direct_integration``;
3. the time of one ``count_law`` on eight frames, and of ``interval_probability`` against scipy's
   ``stats.Normal(...).logcdf(below, above)`` on one posterior grid (161 slopes x 96 jitters x 8 frames).
"""

from __future__ import annotations

import math
import statistics
import sys
import timeit
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).parent))
import count_law_recovery as recovery

from lerobot_phantom.calibration.frame_models import em_truncation


def mean_log_probabilities(quantiles: int) -> list[float]:
    em_truncation.JITTER_QUANTILES = quantiles
    path = Path(f"/tmp/law_choices_{quantiles}.jsonl")
    recovery.run(str(path), "design")
    scores = {}
    for line in path.read_text().splitlines():
        row = recovery.json.loads(line)
        scores.setdefault(row["scenario"], []).append(row["held_out_log_probability"])
    return [statistics.mean(v) if all(map(math.isfinite, v)) else -math.inf for v in scores.values()]


def quantile_deviation(points: int) -> float:
    """Largest relative distance of the median and eighths from a 1536-point grid's, over the test's count sets."""
    rng = np.random.default_rng(62)
    worst = 0.0
    for n, jittered in ((3, False), (4, False), (6, False), (4, True), (8, True)):
        heights = rng.choice([48, 60, 72], n)
        intensities = rng.uniform(0.3, 1.0, n)
        counts = np.floor(
            heights * (0.27 * intensities + (rng.normal(0.0, 1.5 / 48, n) if jittered else 0.0))
        )
        below, above = em_truncation.count_intervals(counts.astype(int), heights, heights // 2)
        values = []
        for grid in (points, 1536):
            em_truncation.JITTER_GRID_POINTS = grid
            _, median, eighths = em_truncation.posterior_law(below, above, int(heights.max()), intensities)
            values.append(np.array([median, *eighths]))
        worst = max(worst, float(np.max(np.abs(values[0] / values[1] - 1))))
    return worst


def main() -> None:
    print(
        "1. mean held-out log probability per frame, design draws (scenarios in count_law_recovery.DESIGN order)"
    )
    for quantiles in (1, 4, 8, 16):
        means = mean_log_probabilities(quantiles)
        print(f"   {quantiles:2d} jitters: " + ", ".join(f"{m:.4f}" for m in means))
    em_truncation.JITTER_QUANTILES = 8
    print("2. largest relative distance of the median and eighths from a 1536-point grid")
    for points in (48, 96):
        print(f"   {points} points: {quantile_deviation(points):.4f}")
    em_truncation.JITTER_GRID_POINTS = 96
    rng = np.random.default_rng(0)
    heights = np.full(8, 48)
    intensities = rng.uniform(0.3, 1.0, 8)
    counts = np.floor(48 * (0.25 * intensities + rng.normal(0.0, 1 / 48, 8))).astype(int)
    law_s = (
        min(timeit.repeat(lambda: em_truncation.count_law(counts, heights, intensities), number=20, repeat=5))
        / 20
    )
    print(f"3. count_law on eight frames: {1e3 * law_s:.2f} ms")
    below, above = em_truncation.count_intervals(counts, heights, heights // 2)
    centre = np.linspace(0.0, 0.5, 161)[:, None, None] * intensities
    jitter = np.geomspace(0.1 / 48, 0.5, 96)[None, :, None]
    ours = min(
        timeit.repeat(
            lambda: em_truncation.interval_probability(below, above, centre, jitter), number=5, repeat=5
        )
    )
    scipy_s = min(
        timeit.repeat(lambda: stats.Normal(mu=centre, sigma=jitter).logcdf(below, above), number=5, repeat=5)
    )
    print(
        f"   interval_probability {1e3 * ours / 5:.1f} ms, scipy's two-argument logcdf {1e3 * scipy_s / 5:.1f} ms "
        f"on 161 x 96 x 8: {scipy_s / ours:.1f}x"
    )


if __name__ == "__main__":
    main()
