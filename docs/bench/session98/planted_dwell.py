"""The dwell camsim's resonance plants, read as the calibration reads a path: per master seed, the cycles per exposure
``ultrasound_blur_pairs`` draws for ``blur_sinusoidal`` (its third draw from the case's generator), the 64 samples of
``(d / 2) sin(2 pi cycles t + phase)`` at each of 16 phases, their 17 quantiles, and the share between the uniform
dwell (0) and the arcsine (1) of ``physics.blur_path_offsets`` whose 17 taps lie nearest them (least squares, in
steps of 0.01): mean, least and most over the phases. Usage: ``PYTHONPATH=. python
docs/bench/session98/planted_dwell.py SEED...``."""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.transforms import physics

TAPS = 17
SHARES = np.linspace(0.0, 1.0, 101)


def nearest_share(positions: np.ndarray, uniform: np.ndarray, arcsine: np.ndarray) -> float:
    quantiles = np.quantile(positions, (np.arange(TAPS) + 0.5) / TAPS)
    errors = [np.mean((quantiles - ((1 - s) * uniform + s * arcsine)) ** 2) for s in SHARES]
    return float(SHARES[int(np.argmin(errors))])


def main() -> None:
    uniform = physics.blur_path_offsets("uniform", TAPS, dtype=torch.float64).numpy()
    arcsine = physics.blur_path_offsets("sinusoidal", TAPS, dtype=torch.float64).numpy()
    t = (np.arange(64) + 0.5) / 64
    for master, _sim, _case, _seed, rng, camera in case_draws(
        "blur_sinusoidal", [int(s) for s in sys.argv[1:]]
    ):
        draws = copy.deepcopy(rng)
        draws.uniform(0, np.pi)  # direction
        draws.uniform(8, 14)  # amplitude
        cycles = draws.uniform(5.2, 8.8)
        shares = [
            nearest_share(np.sin(2 * np.pi * cycles * t + phase) / 2, uniform, arcsine)
            for phase in np.linspace(0, 2 * np.pi, 16, endpoint=False)
        ]
        print(
            f"master {master} ({camera.tone}): {cycles:.3f} cycles; planted dwell share mean {np.mean(shares):.2f}, "
            f"{min(shares):.2f}-{max(shares):.2f} over 16 phases"
        )


if __name__ == "__main__":
    main()
