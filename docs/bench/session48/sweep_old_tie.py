"""``docs/bench/second_camera_sweep.py`` with the tie rule before session 48: ``core.lowest_scoring`` given no margin,
so a preferred group ties only within ``TIE_SHARE``. Measures what change 2 of docs/bench/session48.md does alone.

Usage: ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session48/sweep_old_tie.py SEED [SEED ...]``
"""

import runpy
import sys

from lerobot_phantom.calibration import core

with_margin = core.lowest_scoring
core.lowest_scoring = lambda problem, scores, margin=0.0: with_margin(problem, scores, 0.0)
sys.argv = ["second_camera_sweep.py", *sys.argv[1:]]
runpy.run_path("docs/bench/second_camera_sweep.py", run_name="__main__")
