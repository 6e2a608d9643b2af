"""EM truncation's frame model (calibration/frame_models/em_truncation.py): how many rows a frame loses."""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.em_truncation import (
    TruncationFrames,
    count_law,
    count_probabilities,
    truncation_source_rows,
)

HEIGHT, WIDTH = 48, 8


def truncated_pair(
    rng: np.random.Generator, ratio_per_intensity: float, intensity: float
) -> tuple[Pair, int]:
    """A random frame and its paper truncation with ``int(h r)`` rows lost (the paper's and the transform's floor),
    and that count."""
    clean = torch.from_numpy(rng.uniform(0.0, 1.0, (3, HEIGHT, WIDTH)))
    num = int(HEIGHT * ratio_per_intensity * intensity)
    start = max(0, min(num, HEIGHT - 2 * num))
    attacked = clean[:, torch.from_numpy(truncation_source_rows(HEIGHT, num, start))]
    return Pair(f"pair_{intensity:.3f}", clean, attacked, None, intensity), num


def test_the_count_line_reads_floored_counts_without_bias_and_predicts_beyond_the_fit_intensities():
    """Fit frames at intensities 0.3-0.7, one frame at 0.95: read as n / h and rounded, the line sat half a row
    low and the frame beyond the fit frames was predicted a row short (session 59: a null truncation then named a
    free band start, whose freedom hedged the missing row)."""
    errors, covered = [], 0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        ratio = rng.uniform(0.2, 0.3)
        drawn = [truncated_pair(rng, ratio, s) for s in rng.uniform(0.3, 0.7, 6)]
        beyond, beyond_count = truncated_pair(rng, ratio, 0.95)
        problem = TruncationFrames([pair for pair, _ in drawn] + [beyond], seed)
        fit = problem.fit(frozenset(), np.arange(6))
        assert [problem.placement(False, i)[0] for i in range(6)] == [num for _, num in drawn]
        errors.append(fit.params["ratio_per_intensity"] - ratio)
        counts, weights = problem.predicted_counts(fit, 6)
        covered += beyond_count in counts
        assert np.isclose(weights.sum(), 1.0) and (weights > 0).all()
    # a count is known to one row, so a frame's ratio to 1 / (h s) ~ 0.04 at these intensities; a least-squares
    # line through n / h sat 0.019 low on these draws and missed the frame beyond on 3 of 20
    assert abs(np.mean(errors)) < 0.004, np.mean(errors)
    assert covered == 20, covered


def test_one_line_explains_exact_counts_and_contradicting_counts_get_the_least_jitter():
    heights = np.array([48, 48, 60])
    intensities = np.array([0.4, 0.8, 1.0])
    slope = 0.27
    counts = np.floor(heights * slope * intensities).astype(int)
    low, high, jitter = count_law(counts, heights, intensities)
    assert jitter == 0.0 and low <= slope < high
    # every slope in the range reproduces every count, and a slope just outside it does not
    for a in (low, 0.5 * (low + high), high - 1e-9):
        assert (np.floor(heights * a * intensities) == counts).all()
    assert (np.floor(heights * (high + 1e-6) * intensities) != counts).any()
    # two frames at one intensity, 10 and 12 rows lost: [10, 11) and [12, 13) rows meet with half a row of jitter
    low, high, jitter = count_law(np.array([10, 12]), np.array([48, 48]), np.array([0.8, 0.8]))
    assert np.isclose(jitter, 0.5 / 48) and np.isclose(low, high)
    # a frame at zero intensity that lost rows: only jitter explains it
    assert count_law(np.array([3]), np.array([48]), np.array([0.0]))[2] == 3 / 48


def test_count_probabilities_are_the_floors_of_a_uniform_ratio():
    counts, weights = count_probabilities(0.2, 0.25, 40, 20)  # h r uniform on [8, 10]
    assert counts.tolist() == [8, 9] and np.allclose(weights, [0.5, 0.5])
    # [18, 22], more than the frame's half clipped to it
    counts, weights = count_probabilities(0.45, 0.55, 40, 20)
    assert counts.tolist() == [18, 19, 20] and np.allclose(weights, [0.25, 0.25, 0.5])
    counts, weights = count_probabilities(0.2, 0.2, 40, 20)  # one ratio, one count
    assert counts.tolist() == [8] and weights.tolist() == [1.0]


def test_a_free_band_reaching_into_the_repeated_tail_is_registered_and_an_unchanged_frame_leaves_the_count_free():
    rng = np.random.default_rng(3)
    clean = torch.from_numpy(rng.uniform(0.0, 1.0, (3, HEIGHT, WIDTH)))
    num = 10
    pairs = []
    for start in (5, HEIGHT - 2 * num + 4, HEIGHT - num):  # inside the paper's clamp, into the tail, the tail
        attacked = clean[:, torch.from_numpy(truncation_source_rows(HEIGHT, num, start))]
        pairs.append(Pair(f"start_{start}", clean, attacked, None, 0.8))
    problem = TruncationFrames(pairs, 0)
    assert problem.placement(True, 0) == (num, 5)
    assert problem.placement(True, 1) == (num, HEIGHT - 2 * num + 4)
    assert torch.equal(pairs[2].attacked, clean)
    # the two frames that show their count agree with a line; the unchanged one would have read 0 rows lost
    fit = problem.fit(frozenset({"free_band_position"}), np.arange(3))
    assert fit.params["ratio_jitter"] == 0.0
    low, high = fit.extra["slope_range"]
    assert np.floor(HEIGHT * low * 0.8) == num == np.floor(HEIGHT * (high - 1e-9) * 0.8)
