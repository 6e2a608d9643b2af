"""camsim's filmic tone curve (its ``tone_curve`` on a grey ramp) fitted by the library's log-logistic shoulder
(``tone.shoulder_encode``), without and with a display gamma, its exponent free to 20 (the library's bound is 4):
the parameters and the RMS error in grey levels. Usage: ``PYTHONPATH=.:tests/calibration python
docs/bench/session75/filmic_shoulder_fit.py``."""

import camsim as cs
import numpy as np
import torch
from scipy.optimize import least_squares

from lerobot_phantom.calibration import tone

light = np.linspace(0.001, 1.0, 400)
target = cs.tone_curve(np.stack([light] * 3, -1)[None], cs.Camera(tone="filmic"))[0, :, 0]
for with_gamma in (False, True):

    def residuals(p, with_gamma=with_gamma):
        params = {"shoulder": p[0], "shoulder_exponent": p[1]}
        encoded = tone.shoulder_encode(torch.from_numpy(light), params, p[2] if with_gamma else None)
        return 255 * (encoded.numpy() - target)

    start, low, high = [1.0, 1.0], [0.0, 0.25], [500.0, 20.0]
    if with_gamma:
        start, low, high = [*start, 1.0], [*low, 0.3], [*high, 4.0]
    fit = least_squares(residuals, start, bounds=(low, high))
    names = ("shoulder", "shoulder_exponent", "gamma")
    print(
        f"{'with' if with_gamma else 'without'} gamma: "
        + ", ".join(f"{n} {v:.3f}" for n, v in zip(names, fit.x, strict=False))
        + f"; RMS {np.sqrt(np.mean(fit.fun**2)):.3f} grey levels"
    )
