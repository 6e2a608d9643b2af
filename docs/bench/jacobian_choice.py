"""Finite differences or torch forward mode for the calibration fits' Jacobians: CPU and agreement, in one run.

Runs ``lerobot-phantom-calibrate`` in this process on each shared input of ``calibration_shared_data.py`` (seed 0,
the CLI's defaults) twice: first with ``core.JACOBIAN = "2-point"`` (scipy's finite differences), then with
``"forward"`` (torch forward mode under vmap). Fits that pass their own ``jacobian`` are the same in both: models
torch cannot differentiate, and since 0bc1c81 the stripe fits (``stripes.STRIPE_JACOBIAN``), so the stripe table's
comparison is ``output_0bc1c81.txt``'s. Prints per input each run's process CPU seconds, their ratio, the written
model's held-out RMSE and named effects, and the largest relative difference between the two runs' fitted
parameters. MEASURED_DIR is ``../shared/measured`` (third-party data, not in this repository).

    OMP_NUM_THREADS=1 python docs/bench/jacobian_choice.py ../shared/measured SCRATCH_DIR

``docs/bench/jacobian_choice/output_90c10e3.txt`` is an earlier form of this bench, the laser captures alone, run
at 90c10e3 where only the capture fits had moved to finite differences.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import torch
from calibration_shared_data import RUNS

from lerobot_phantom.calibration import core
from lerobot_phantom.calibration.cli import main as calibrate_cli


def run(measured: Path, out: Path, attack: str, relative: str, flags: list[str]) -> tuple[float, dict]:
    start = time.process_time()
    calibrate_cli(["--attack", attack, "--measured", str(measured / relative), *flags, "--out", str(out)])
    return time.process_time() - start, json.loads((out / "report.json").read_text())


def main(measured: Path, scratch: Path) -> None:
    torch.set_num_threads(1)
    scratch.mkdir(parents=True, exist_ok=False)
    for name, (attack, relative, flags) in RUNS.items():
        runs = {}
        for jacobian in ("2-point", "forward"):
            core.JACOBIAN = jacobian
            runs[jacobian] = run(measured, scratch / f"{name}_{jacobian}", attack, relative, flags)
        print_comparison(name, runs)


def print_comparison(name: str, runs: dict[str, tuple[float, dict]]) -> None:
    """Each run's CPU seconds, written held-out RMSE and named effects; then the second run's CPU over the first's
    and the largest relative difference between their fitted parameters. ``runs``: Jacobian -> (CPU, report)."""
    for jacobian, (cpu, report) in runs.items():
        rmse = report["extended"]["heldout_rmse_interval"]
        print(
            f"{name} {jacobian}: {cpu:.1f} s CPU; written {rmse['estimate']:.4f} "
            f"[{rmse['low']:.4f}, {rmse['high']:.4f}]; named {report['extended']['effects']}"
        )
    (first, (first_cpu, before)), (second, (second_cpu, after)) = runs.items()
    differences = [
        abs(after["extended"]["params"].get(k, float("nan")) - v) / max(abs(v), 1e-12)
        for k, v in before["extended"]["params"].items()
    ]
    print(
        f"{name}: CPU {second} / {first} {second_cpu / first_cpu:.2f}; largest relative difference over "
        f"{len(differences)} fitted parameters {max(differences):.2e}",
        flush=True,
    )


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
