"""The dwell read's objective along the dwell share: per camsim blur case and master seed, the resonance with a
shouldered tone curve (``sinusoidal_motion`` + ``tone_shoulder``) fitted on the calibration's fit pairs, then at
each dwell share from 0 (a constant-speed sweep) to 1 (the arcsine) the path and tone curve refitted with the share
held (``BlurFrames.dwell_residuals``, started where ``dwell_share`` starts them), and the fit pairs' RMSE (grey
levels); the share ``dwell_share`` returns beside it. Usage: ``PYTHONPATH=. python
docs/bench/session98/dwell_profile.py CASE[,CASE...] SEED...``."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session83"))
from across_share import each_case_draw

from lerobot_phantom.calibration.core import fit_least_squares

SHARES = np.linspace(0.0, 1.0, 11)
MODEL = frozenset({"sinusoidal_motion", "tone_shoulder"})


def print_profile(label: str, problem, items, _camera) -> None:
    fit = problem.fit(MODEL, items)
    start = problem.dwell_start(fit)
    specs = problem.dwell_specs()
    read = problem.dwell_share(fit, items)
    written = problem.rmse(fit, items)
    profile = []
    for share in SHARES:
        params = fit_least_squares(
            specs,
            lambda p, share=share: problem.dwell_residuals(p, items, share),
            warm=start,
            jacobian="2-point",
            max_nfev=30,
        )
        held = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
        residual = problem.dwell_residuals(held, items, share).detach().numpy()
        profile.append(f"{share:.1f}:{np.sqrt(np.mean(residual**2)) * 255:.3f}")
    print(
        f"{label}: model RMSE {written:.3f}, dwell_share {read:.3f}; RMSE at share {' '.join(profile)}",
        flush=True,
    )


def main() -> None:
    each_case_draw(
        print_profile, "dwell share: fit pairs' RMSE (grey levels) with the path and tone curve refitted"
    )


if __name__ == "__main__":
    main()
