"""How closely the package's shoulder curve (``calibration/tone.py``, no display gamma) can follow camsim's filmic
tone curve (ACES fit on a 4x pre-gain, then sRGB): a least-squares fit in 8-bit values over 400 points spread
evenly in the encoded value. Usage: ``PYTHONPATH=. python docs/bench/camsim_filmic_shoulder_fit.py``."""

from __future__ import annotations

import sys

import numpy as np
import torch
from scipy.optimize import least_squares

from lerobot_phantom.calibration.tone import shoulder_encode

sys.path.insert(0, "tests/calibration")
import camsim


def main() -> None:
    camera = camsim.Camera(tone="filmic")
    x = np.linspace(0.0, 1.0, 4001)[1:]
    encoded = camsim.tone_curve(x, camera)
    points = np.interp(np.linspace(0.01, 0.99, 400), encoded, x)
    target = camsim.tone_curve(points, camera)

    def residuals(p: np.ndarray) -> np.ndarray:
        params = {"shoulder": p[0], "shoulder_exponent": p[1]}
        return shoulder_encode(torch.from_numpy(points), params).numpy() - target

    fits = [
        least_squares(residuals, start, bounds=([0.0, 0.25], [500.0, 4.0])) for start in ([1, 1], [30, 1.5])
    ]
    best = min(fits, key=lambda r: r.cost)
    rms, worst = 255 * np.sqrt(np.mean(best.fun**2)), 255 * np.abs(best.fun).max()
    print(
        f"shoulder {best.x[0]:.1f}, knee exponent {best.x[1]:.2f}: {rms:.2f} grey levels RMS, {worst:.2f} at most"
    )


if __name__ == "__main__":
    main()
