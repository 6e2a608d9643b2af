"""Fits laser blinding models on every pair of a frame-pair folder (the calibration's sampled pixels), each model
starting from the one before it, and prints each one's RMSE over all pixels and its parameters.

Usage: ``PYTHONPATH=. python docs/bench/session69/fit_all_pairs.py PAIRS_DIR MAX_SIDE EFFECTS[,EFFECT...]...``
(``colour_correction`` models need a checkout with ``colour_correction_attempt.patch`` applied: main reverted it.)
"""

import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames

folder = Path(sys.argv[1])
pairs = load_pairs(folder, max_side=int(sys.argv[2]))
problem = BlindingFrames(pairs, 0)
items = np.arange(len(pairs))
fit = None
for model in sys.argv[3:]:
    fit = problem.fit(frozenset(model.split(",")), items, fit)
    sse, n = problem.squared_errors(fit, items)
    print(
        f"{model}: RMSE {np.sqrt(sse / n):.2f}", {k: round(v, 3) for k, v in fit.params.items()}, flush=True
    )
