"""Laser blinding frame pairs: the model with linear light and the halo, without and with auto_exposure, fitted on
all pairs; per pair, the mean residual (attacked - predicted, grey levels) in rings of frame pixels around the spot.

usage: python blinding_residual_rings.py PAIRS_FOLDER [SEED] [EXTRA_EFFECT,...]   (extra effects join both models,
e.g. tone_shoulder for a filmic camera)
"""

import itertools
import sys
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.frame_models import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames, pattern_centre

RINGS_PX = (0, 4, 8, 16, 32, 64, 1e9)


def ring_means(residual: torch.Tensor, radius: torch.Tensor) -> list[float]:
    means = []
    for inner, outer in itertools.pairwise(RINGS_PX):
        ring = (radius >= inner) & (radius < outer)
        means.append(float(residual[:, ring].mean()) if ring.any() else float("nan"))
    return means


def main(folder: Path, seed: int, extra: list[str]) -> None:
    pairs = load_pairs(folder, max_side=256)
    problem = BlindingFrames(pairs, seed)
    items = np.arange(len(pairs))
    print("rings (frame px):", RINGS_PX)
    for effects in (
        ["linear_light_saturation", "halo_power_law", *extra],
        ["linear_light_saturation", "halo_power_law", *extra, "auto_exposure"],
    ):
        fit = problem.fit(frozenset(effects), items)
        print(effects, {k: round(float(v), 4) for k, v in fit.params.items()})
        for index, pair in enumerate(pairs):
            residual = 255 * (pair.attacked - problem.predict_pair(fit, index))
            cx, cy = pattern_centre(pair.pattern)
            height, width = pair.attacked.shape[1:]
            ys, xs = torch.meshgrid(
                torch.arange(height, dtype=torch.float64),
                torch.arange(width, dtype=torch.float64),
                indexing="ij",
            )
            means = ring_means(residual, torch.hypot(xs - cx, ys - cy))
            print(
                f"  pair {index} intensity {pair.intensity:.2f} rmse {float(residual.pow(2).mean().sqrt()):.2f}"
                " mean residual by ring",
                " ".join(f"{m:+.2f}" for m in means),
            )


if __name__ == "__main__":
    main(
        Path(sys.argv[1]),
        int(sys.argv[2]) if len(sys.argv) > 2 else 0,
        sys.argv[3].split(",") if len(sys.argv) > 3 else [],
    )
