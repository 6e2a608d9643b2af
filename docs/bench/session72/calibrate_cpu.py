"""One calibration of a frame-pairs folder, printing the named effects, wall and process CPU time.
Usage: ``PYTHONPATH=TREE python docs/bench/session72/calibrate_cpu.py PAIRS OUT SEED ATTACK`` (TREE: the checkout
whose package is timed)."""

import sys
import time

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

pairs, out, seed, attack = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
wall, cpu = time.perf_counter(), time.process_time()
report = calibrate(CalibrateConfig(attack=attack, measured=pairs, out=out, seed=seed))
print(
    report["extended"]["effects"],
    f"wall {time.perf_counter() - wall:.1f} s cpu {time.process_time() - cpu:.1f} s",
)
