"""Exact Jacobians for stripe fits: torch forward mode against reverse mode, CPU and agreement, in one run.

Runs ``lerobot-phantom-calibrate`` on one stripe table twice in this process, first with
``stripes.STRIPE_JACOBIAN = "forward"`` (torch.func.jacfwd), then ``"reverse"`` (torch.func.jacrev), and prints each
run's process CPU seconds, their ratio, the written model's held-out RMSE and named effects, and the largest
relative difference between the two runs' fitted parameters. Forward mode runs every elementwise op that mixes a
parameter with a plain tensor or a Python number as a Python decomposition in torch 2.10; reverse mode does not.

    OMP_NUM_THREADS=1 python docs/bench/stripe_jacobian.py TABLE.csv SCRATCH_DIR --image_height 720 \\
        --exposure_unit_s 1e-4
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import torch

from lerobot_phantom.calibration import stripes
from lerobot_phantom.calibration.cli import main as calibrate_cli


def main(table: str, scratch: Path, flags: list[str]) -> None:
    torch.set_num_threads(1)
    scratch.mkdir(parents=True, exist_ok=False)
    runs = {}
    for jacobian in ("forward", "reverse"):
        stripes.STRIPE_JACOBIAN = jacobian
        out = scratch / jacobian
        start = time.process_time()
        calibrate_cli(["--attack", "laser_color_strip", "--measured", table, *flags, "--out", str(out)])
        runs[jacobian] = (time.process_time() - start, json.loads((out / "report.json").read_text()))
    for jacobian, (cpu, report) in runs.items():
        rmse = report["extended"]["heldout_rmse_interval"]
        print(
            f"{jacobian}: {cpu:.1f} s CPU; written {rmse['estimate']:.4f} [{rmse['low']:.4f}, {rmse['high']:.4f}]; "
            f"named {report['extended']['effects']}"
        )
    (forward_cpu, forward), (reverse_cpu, reverse) = runs.values()
    differences = [
        abs(reverse["extended"]["params"].get(k, float("nan")) - v) / max(abs(v), 1e-12)
        for k, v in forward["extended"]["params"].items()
    ]
    print(
        f"CPU reverse / forward {reverse_cpu / forward_cpu:.2f}; largest relative difference over "
        f"{len(differences)} fitted parameters {max(differences):.2e}",
        flush=True,
    )


if __name__ == "__main__":
    main(sys.argv[1], Path(sys.argv[2]), sys.argv[3:])
