"""CPU of one laser blinding calibration (process user + system time, ``resource.getrusage``), by the package found
first on ``sys.path``: run it once per checkout with ``PYTHONPATH=CHECKOUT``, alone on the machine.

Usage: ``PYTHONPATH=CHECKOUT python docs/bench/session68/blinding_cost.py PAIRS_DIR SEED OUT_DIR``
"""

from __future__ import annotations

import resource
import sys

import lerobot_phantom
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main() -> None:
    pairs, seed, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    before = resource.getrusage(resource.RUSAGE_SELF)
    report = calibrate(CalibrateConfig(attack="laser_blinding", measured=pairs, out=out, seed=seed))
    after = resource.getrusage(resource.RUSAGE_SELF)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    print(
        f"{lerobot_phantom.__file__}: {pairs} named {report['extended']['effects']}, {cpu:.1f} s CPU",
        flush=True,
    )


if __name__ == "__main__":
    main()
