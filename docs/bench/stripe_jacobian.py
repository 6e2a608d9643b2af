"""Exact Jacobians for stripe fits: torch forward mode against reverse mode, CPU and agreement, in one run.

Runs ``lerobot-phantom-calibrate`` on one stripe table twice in this process, first with
``stripes.STRIPE_JACOBIAN = "forward"`` (torch.func.jacfwd), then ``"reverse"`` (torch.func.jacrev), and prints each
run's process CPU seconds, their ratio, the written model's held-out RMSE and named effects, and the largest
relative difference between the two runs' fitted parameters. Forward mode runs every elementwise op that mixes a
parameter with a plain tensor or a Python number as a Python decomposition in torch 2.10; reverse mode does not.

    OMP_NUM_THREADS=1 python docs/bench/stripe_jacobian.py TABLE.csv SCRATCH_DIR --image_height 720 \\
        --exposure_unit_s 1e-4

(``session28/stripe_jacobian_logitech_c1.txt`` was printed by this script's first form at 25e931b, before
``phase_drift``, whose own fit takes finite differences in both runs; its lines are worded without the table's name.)
"""

from __future__ import annotations

import sys
from pathlib import Path

import torch
from jacobian_choice import print_comparison, run

from lerobot_phantom.calibration import stripes


def main(table: str, scratch: Path, flags: list[str]) -> None:
    torch.set_num_threads(1)
    scratch.mkdir(parents=True, exist_ok=False)
    runs = {}
    for jacobian in ("forward", "reverse"):
        stripes.STRIPE_JACOBIAN = jacobian
        runs[jacobian] = run(
            Path(table).parent, scratch / jacobian, "laser_color_strip", Path(table).name, flags
        )
    print_comparison(Path(table).name, runs)


if __name__ == "__main__":
    main(sys.argv[1], Path(sys.argv[2]), sys.argv[3:])
