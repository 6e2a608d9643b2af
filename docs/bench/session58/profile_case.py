"""One kit calibration under cProfile, the 45 largest cumulative times printed and the stats kept in OUT:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 python docs/bench/session58/profile_case.py laser_color_strip exposure_overlap 62 OUT

(EFFECTS: planted effects joined by "+"; session 58 ran this case beside the suite: profile_case62_fa4192d.txt)."""

import cProfile
import pstats
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[3] / "tests" / "calibration"))
import calibration_testkit as kit

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

attack, effects, seed, out = (
    sys.argv[1],
    set(filter(None, sys.argv[2].split("+"))),
    int(sys.argv[3]),
    Path(sys.argv[4]),
)
measured = out / "measured"
measured.mkdir(parents=True)
kit.RENDERERS[attack](measured, effects, seed)
prof = cProfile.Profile()
t = time.perf_counter()
prof.enable()
report = calibrate(CalibrateConfig(attack=attack, measured=str(measured), out=str(out / "out"), seed=seed))
prof.disable()
print("wall", time.perf_counter() - t, "named", report["extended"]["effects"])
prof.dump_stats(str(out / "prof.pstats"))
pstats.Stats(prof).sort_stats("cumulative").print_stats(45)
