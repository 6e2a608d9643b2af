"""How many of the stripe kernel check's 12 conditions keep a frame under the interior rule, over 300 drawn
cameras (session 62; 60 simulated frames per condition, which can only keep fewer than the test's 300). Run from a
checkout's root with ``PYTHONPATH`` at it and ``STRIPES_SEED`` set to anything (the test module reads it):

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 STRIPES_SEED=1 python docs/bench/session62/interior_kept.py
"""

import collections
import sys

import numpy as np

sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as t

seeds = np.random.default_rng(62062).integers(0, 2**32, 300)
hist = collections.Counter()
for s in seeds:
    c = t.kernel_against_simulator(int(s), "interior", 60)
    k = int(np.isfinite(t.kernel_miss(c)).sum())
    hist[k] += 1
    if k < 6:
        print("few", s, k, flush=True)
print(sorted(hist.items()))
