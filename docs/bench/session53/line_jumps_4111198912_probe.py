"""Which fits on drawn camera 4111198912 lit (sampled pulses) 4e18abf's line jump moved: every call of
``StripeProblem.threshold_at_flat_floor`` that returned a lower squared error than it was given (a floor move ties
it), with the training rows' count, the frame rule, the model, and the threshold, offset and row time before -> after.

Usage (at 4e18abf): ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session53/line_jumps_4111198912_probe.py``
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

os.environ.setdefault("STRIPES_SEED", "4111198912")
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

from lerobot_phantom.calibration import stripes

original = stripes.StripeProblem.threshold_at_flat_floor


def logged(self, effects, specs, items, rule, error, params):
    out_error, out_params = original(self, effects, specs, items, rule, error, params)
    moved = "threshold_s" in params and out_error < error * (1 - 1e-6)
    if moved:
        print(
            f"n={len(items)} {rule:8s} {'+'.join(sorted(e[:9] for e in effects))}: sse {error:.3f} -> {out_error:.3f} "
            f"threshold {params['threshold_s'] * 1e6:.2f} -> {out_params['threshold_s'] * 1e6:.2f} us, offset "
            f"{params.get('integration_offset_s', np.nan) * 1e6:.2f} -> {out_params.get('integration_offset_s', np.nan) * 1e6:.2f}, row time "
            f"{params['row_time_s'] * 1e6:.2f} -> {out_params['row_time_s'] * 1e6:.2f}",
            flush=True,
        )
    return out_error, out_params


stripes.StripeProblem.threshold_at_flat_floor = logged
with tempfile.TemporaryDirectory() as tmp:
    camera, report = ts.calibrate_drawn_camera(
        Path(tmp), 4111198912, "lit", "exposure_us", calibration_seed=912, bootstrap=10, pulses="sampled"
    )
print("held-out", report["extended"]["heldout_rmse"], sorted(report["extended"]["effects"]))
