"""How well a blur draw's frames measure its dwell: the profile of ``BlurFrames.dwell_share``'s fit. At each fixed
share (0: a constant-speed sweep's uniform dwell, 1: a sinusoid's arcsine) the path and the shouldered tone curve
are refitted on the calibration's fit pairs by the package's own residuals (``BlurFrames.dwell_residuals``,
``dwell_specs``, ``dwell_start``), started from the resonance fitted with ``tone_shoulder``; the fit's RMSE is
printed per share, beside the package's own read and where the clean frames' grey levels lie (a filmic camera
stores its scene high on its curve, where contrast is compressed).

Usage: ``PYTHONPATH=. python docs/bench/session86/dwell_profile.py CASE:CASE_SEED...`` (case seeds, as
``run_camsim_case.py`` prints them).
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.core import fit_least_squares

SHARES = np.linspace(0.0, 1.0, 11)
RESONANCE = frozenset({"sinusoidal_motion", "tone_shoulder"})


def profile(name: str, case_seed: int) -> None:
    import test_independent_sim as sim

    with tempfile.TemporaryDirectory() as folder:
        problem, items, _ = sim.drawn_split(name, case_seed, Path(folder))
        camera = sim.case_camera(sim.CASE_BY_NAME[name], case_seed)[2]
        clean = 255 * np.concatenate([problem.pairs[int(i)].clean.numpy().ravel() for i in items])
        fit = problem.fit(RESONANCE, items)
        print(
            f"{name} case seed {case_seed} ({camera.tone}): clean grey levels p10 {np.quantile(clean, 0.1):.0f}, "
            f"median {np.median(clean):.0f}, p90 {np.quantile(clean, 0.9):.0f}; the package's dwell read "
            f"{problem.dwell_share(fit, items):.3f}",
            flush=True,
        )
        specs, start = problem.dwell_specs(), problem.dwell_start(fit)
        rmse = []
        for share in SHARES:
            p = fit_least_squares(
                specs,
                lambda p, share=float(share): problem.dwell_residuals(p, items, share),
                warm=start,
                jacobian="2-point",
                max_nfev=60,
            )
            with torch.no_grad():
                params = {k: torch.tensor(v, dtype=torch.float64) for k, v in p.items()}
                residual = problem.dwell_residuals(params, items, float(share))
            rmse.append(255 * float(residual.pow(2).mean().sqrt()))
            print(
                f"  share {share:.1f}: RMSE {rmse[-1]:.3f}, path {np.hypot(p['dx_ref_px'], p['dy_ref_px']):.1f} ref px",
                flush=True,
            )
        print(
            f"  best share {SHARES[int(np.argmin(rmse))]:.1f}; RMSE at arcsine / at uniform "
            f"{rmse[-1] / rmse[0]:.3f}; largest / smallest over the profile {max(rmse) / min(rmse):.3f}",
            flush=True,
        )


def main() -> None:
    sys.path[:0] = [str(Path(__file__).resolve().parents[3] / "tests" / sub) for sub in ("calibration", "")]
    os.environ.setdefault(
        "CAMSIM_SEED", "0"
    )  # the test module reads a master seed; the case seeds given decide
    for arg in sys.argv[1:]:
        name, case_seed = arg.split(":")
        profile(name, int(case_seed))


if __name__ == "__main__":
    main()
