"""cProfile of one calibration: ``python docs/bench/session72/profile_calibration.py PAIRS OUT SEED ATTACK`` prints
the 45 calls with the most cumulative time and the 30 with the most own time, and writes OUT.prof."""

import cProfile
import pstats
import sys
import time

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

pairs, out, seed, attack = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
pr = cProfile.Profile()
t = time.perf_counter()
pr.enable()
r = calibrate(CalibrateConfig(attack=attack, measured=pairs, out=out, seed=seed))
pr.disable()
print(r["extended"]["effects"], f"{time.perf_counter() - t:.1f} s")
pr.dump_stats(out + ".prof")
st = pstats.Stats(pr)
st.sort_stats("cumulative").print_stats(45)
st.sort_stats("tottime").print_stats(30)
