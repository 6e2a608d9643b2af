"""What ``light_spread`` costs a light projection frame fit: CPU seconds of one fit of additive light with and
without the spread, on six synthetic pairs (``calibration_testkit.projection_pairs_with_spread_light``, scipy's
blur of 1 px at 50 px wide) upsampled to a working size of 64 and 256 pixels (the calibrate CLI's default
``--max-side``), one thread, best of three.

Usage: ``PYTHONPATH=.:tests/calibration python docs/bench/session32/spread_fit_cost.py`` from the repository root.
"""

from __future__ import annotations

import time

import numpy as np
import torch
from calibration_testkit import projection_pairs_with_spread_light

from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames


def resized(pairs: list[Pair], longer_side: int) -> list[Pair]:
    height = round(pairs[0].height * longer_side / pairs[0].width)

    def scale(image: torch.Tensor) -> torch.Tensor:
        return torch.nn.functional.interpolate(image[None], size=(height, longer_side), mode="bilinear")[0]

    return [Pair(p.name, scale(p.clean), scale(p.attacked), scale(p.pattern), p.intensity) for p in pairs]


def best_cpu_seconds(problem: ProjectionFrames, effects: frozenset[str]) -> tuple[float, dict]:
    times, fit = [], None
    for _ in range(3):
        started = time.process_time()
        fit = problem.fit(effects, np.arange(problem.n_items))
        times.append(time.process_time() - started)
    return min(times), fit.params


def main() -> None:
    torch.set_num_threads(1)
    pairs = projection_pairs_with_spread_light(1.0, seed=3)
    for side in (64, 256):
        problem = ProjectionFrames(resized(pairs, side), seed=3)
        without, _ = best_cpu_seconds(problem, frozenset({"additive_light"}))
        with_spread, params = best_cpu_seconds(problem, frozenset({"additive_light", "light_spread"}))
        print(
            f"{side} px wide (kernel radius {problem.spread_radius} px): additive light {without:.3f} s, "
            f"+ light_spread {with_spread:.3f} s ({with_spread / without:.1f}x); fitted spread "
            f"{params['spread_ref_px']:.2f} reference px (planted {256 / 50:.2f})"
        )


if __name__ == "__main__":
    main()
