"""The error of fold 2 of drawn camera 531200696's selection (lit frames; the split and folds the calibration makes)
along the threshold: at each threshold of a grid, threshold + offset refitted with the threshold held (row time and
offset free, started on the line offset = 18 us + 2 threshold), its training squared error and the mean absolute
error on the rows the fold validates. Also the training rows' pulse on-times and exposures.

Usage: ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session52/fold2_ridge_probe.py``
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

os.environ["STRIPES_SEED"] = "531200696"
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

from lerobot_phantom.calibration.core import Fit, fit_least_squares, kfold, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

SEED = 531200696
with tempfile.TemporaryDirectory() as root:
    table = Path(root) / "table.csv"
    camera = ts.drawn_camera_table(table, SEED, "lit", "exposure_us")
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
fit_items, heldout = seeded_split(problem.n_items, 0.2, SEED % 1000)
train, validated = kfold(fit_items, 4, SEED % 1000 + 1, 2500)[2]
effects = frozenset({"exposure_overlap", "detection_threshold", "integration_offset"})
on_time = problem.duty / problem.frequency_hz
print("training on-times (us)", np.unique(np.round(on_time[train] * 1e6, 1)))
print("training exposures (us)", np.unique(problem.exposure_s[train] * 1e6))
target = torch.as_tensor(problem.rows[train].copy())
specs = [p for p in problem.param_specs(effects) if p.name != "threshold_s"]


def fit_at(threshold: float) -> Fit:
    held = {"threshold_s": torch.tensor(threshold, dtype=torch.float64)}
    warm = {"row_time_s": 15.83e-6, "integration_offset_s": 18e-6 + 2 * threshold}
    params = fit_least_squares(
        specs,
        lambda p: problem.predict(effects, p | held, train, "lit") - target,
        warm=warm,
        jacobian="reverse",
    )
    return Fit(effects, params | {"threshold_s": threshold}, {"frames": "lit"})


for threshold in np.linspace(15e-6, 80e-6, 27):
    fit = fit_at(float(threshold))
    sse = float(np.sum(problem.residual(fit, train) ** 2))
    validated_error = float(np.mean(np.abs(problem.residual(fit, validated))))
    print(
        f"threshold {threshold * 1e6:6.2f} us offset {fit.params['integration_offset_s'] * 1e6:7.2f} us row time "
        f"{fit.params['row_time_s'] * 1e6:6.3f} us training squared error {sse:12.4f} validated mean abs "
        f"{validated_error:7.2f} rows"
    )
