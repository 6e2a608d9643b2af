"""One camsim case rendered on the camera its master seed draws, changed in one stated way, then calibrated as the
test does (``session64/run_camsim_case.py``'s step): ``--tone T`` replaces the camera's tone curve; ``--no-mosaic``
samples all three channels at every pixel (no Bayer mosaic, no demosaic).

Usage: ``CAMSIM_CCM=1 PYTHONPATH=. python docs/bench/session71/ccm_take_variants.py CASE OUTDIR SEED... [--tone T]
[--no-mosaic]`` (OUTDIR/bt_SEED must not exist)."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(1, str(Path(__file__).resolve().parents[1] / "session64"))
sys.path.insert(2, "tests/calibration")
sys.path.insert(3, "tests")
import camsim
from camsim_case_cameras import case_draws
from run_camsim_case import render_and_calibrate


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("out", type=Path)
    parser.add_argument("seeds", type=int, nargs="+")
    parser.add_argument("--tone")
    parser.add_argument("--no-mosaic", action="store_true")
    args = parser.parse_args()
    if args.no_mosaic:
        camsim.mosaic = lambda linear: linear.copy()
        camsim.demosaic = lambda raw: raw
    for master, _sim, case, seed, rng, camera in case_draws(args.case, args.seeds):
        if args.tone:
            camera = dataclasses.replace(camera, tone=args.tone)
        render_and_calibrate(args.out, args.case, master, case, seed, rng, camera)


if __name__ == "__main__":
    main()
