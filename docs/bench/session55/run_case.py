"""Calibrate one case of the calibration kit (tests/calibration/calibration_testkit.py) and time it.

    python run_case.py ATTACK PLANTED SEED OUT      (PLANTED: effects joined by "+"; OUT must not exist)

The package is the one on PYTHONPATH (its path is printed). OUT/measured holds the kit's frames, OUT/out the outputs.
"""

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
import calibration_testkit as kit

import lerobot_phantom
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main() -> None:
    attack, planted, seed, out = (
        sys.argv[1],
        set(filter(None, sys.argv[2].split("+"))),
        int(sys.argv[3]),
        Path(sys.argv[4]),
    )
    measured = out / "measured"
    measured.mkdir(parents=True)
    kit.RENDERERS[attack](measured, planted, seed)
    began = time.perf_counter()
    calibrate(CalibrateConfig(attack=attack, measured=str(measured), out=str(out / "out"), seed=seed))
    print(lerobot_phantom.__file__, attack, sys.argv[2], seed, f"{time.perf_counter() - began:.1f} s")


if __name__ == "__main__":
    main()
