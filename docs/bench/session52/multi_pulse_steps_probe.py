"""A fit-search gap seen while writing the bracketed-threshold test: ``threshold_regimes_beside`` takes a threshold's
steps to be ``min(on-time, window)``, but a window that holds k pulses collects k on-times, a step too. The table:
test_stripes' bracketed-threshold table with a 2375 us exposure added (533.2 Hz 1%: two 18.75 us pulses in a window,
37.5 us; 1040 Hz 1%: three 9.62 us pulses, 28.8 us). Printed: the fit from threshold starts of 20 and 46 us (offset
moved along, as the test does), and the squared error along the line threshold + d, offset + 2 d through the 46 us
fit, which shows the flats between those steps.

Usage: ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session52/multi_pulse_steps_probe.py``
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

os.environ.setdefault("STRIPES_SEED", "52")
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.stripes import StripeProblem

with tempfile.TemporaryDirectory() as root:
    table = Path(root) / "table.csv"
    truth = ts.bracketed_threshold_table(table, np.random.default_rng(52), exposures_us=(79, 246, 765, 2375))
    problem = StripeProblem(table, image_height=None, exposure_unit_s=None)
effects = frozenset({"exposure_overlap", "integration_offset", "detection_threshold"})
items = np.arange(problem.n_items)
target = torch.as_tensor(problem.rows.copy())
fits = {}
for start_us in (20.0, 46.0):
    moved = start_us * 1e-6 - truth["threshold_s"]
    start = {
        **truth,
        "threshold_s": start_us * 1e-6,
        "integration_offset_s": truth["integration_offset_s"] + 2 * moved,
    }
    fit = problem.fit(effects, items, Fit(effects, start, {"frames": "lit"}))
    sse = float(np.sum(problem.residual(fit, items) ** 2))
    fits[start_us] = fit
    print(
        f"start {start_us} us -> threshold {fit.params['threshold_s'] * 1e6:.2f} us, offset "
        f"{fit.params['integration_offset_s'] * 1e6:.2f} us, row time {fit.params['row_time_s'] * 1e6:.3f} us, "
        f"squared error {sse:.1f}"
    )
params = fits[46.0].params
print("along threshold + d, offset + 2 d through the 46 us start's fit:")
for threshold in np.arange(12e-6, 54e-6, 2e-6):
    d = threshold - params["threshold_s"]
    values = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
    values["threshold_s"] = torch.tensor(threshold, dtype=torch.float64)
    values["integration_offset_s"] = torch.tensor(params["integration_offset_s"] + 2 * d, dtype=torch.float64)
    with torch.no_grad():
        sse = float(((problem.predict(effects, values, items, "lit") - target) ** 2).sum())
    print(f"  threshold {threshold * 1e6:5.1f} us  squared error {sse:12.1f}")
