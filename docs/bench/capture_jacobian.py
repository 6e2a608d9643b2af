"""Forward-mode autodiff or finite differences for the laser-capture fits: CPU and agreement, in one run.

Calibrates the laser captures under MEASURED_DIR (``../shared/measured/blinding``, third-party data that is not in
this repository) twice in this process with the CLI's defaults (seed 0): first with the Jacobian by scipy's 2-point
finite differences, then by torch forward mode (``CaptureProblem.autodiff_jacobian``). Prints each run's process
CPU seconds, their ratio, the held-out figures and named effects of both, and the largest relative difference
between their fitted parameters.

    OMP_NUM_THREADS=1 python docs/bench/capture_jacobian.py ../shared/measured/blinding SCRATCH_DIR
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import torch

from lerobot_phantom.calibration.captures import CaptureProblem
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def run(measured: Path, out: Path, *, autodiff: bool) -> tuple[float, dict]:
    CaptureProblem.autodiff_jacobian = autodiff
    start = time.process_time()
    report = calibrate(CalibrateConfig(attack="laser_blinding", measured=str(measured), out=str(out), seed=0))
    return time.process_time() - start, report


def main(measured: Path, scratch: Path) -> None:
    torch.set_num_threads(1)
    scratch.mkdir(parents=True, exist_ok=False)
    runs = {
        "finite differences": run(measured, scratch / "finite_differences", autodiff=False),
        "forward mode": run(measured, scratch / "forward_mode", autodiff=True),
    }
    for name, (cpu, report) in runs.items():
        rmse = report["extended"]["heldout_rmse_interval"]
        print(
            f"{name}: {cpu:.1f} s CPU; held-out {report['base']['heldout_rmse_interval']['estimate']:.4f} -> "
            f"{rmse['estimate']:.4f} [{rmse['low']:.4f}, {rmse['high']:.4f}]; named {report['extended']['effects']}"
        )
    (fd_cpu, fd), (ad_cpu, ad) = runs.values()
    print(f"CPU ratio forward / finite differences: {ad_cpu / fd_cpu:.2f}")
    differences = [
        abs(fd["extended"]["params"][k] - v) / max(abs(v), 1e-12) for k, v in ad["extended"]["params"].items()
    ]
    print(f"largest relative difference over {len(differences)} fitted parameters: {max(differences):.2e}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
