"""Drawn camera 1211740460, interior frames (``test_stripes.calibrate_drawn_camera``'s table and split): the
noise-free threshold + offset model fitted from two starts under the interior rule, the basin a first fit ends in
(threshold 3.75 us) and the one the four-effect fit reaches (threshold 44.24 us, offset 90.58 us), with each fit's
squared error on the fit rows and its held-out RMSE. Run from a checkout:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session41/trials/two_basins_1211740460.py
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

SEED, FRAMES = 1211740460, "interior"
os.environ["STRIPES_SEED"] = str(SEED)
sys.path.insert(0, str(Path("tests/calibration").resolve()))
import test_stripes  # noqa: E402

from lerobot_phantom.calibration.core import Fit, seeded_split  # noqa: E402
from lerobot_phantom.calibration.stripes import StripeProblem  # noqa: E402

rng = np.random.default_rng([SEED, 2, len(FRAMES)])
camera = test_stripes.draw_camera(rng, FRAMES)
with tempfile.TemporaryDirectory() as tmp:
    table = Path(tmp) / "second_camera.csv"
    test_stripes.write_table(table, camera, rng, n_rows=60, frames=60, style="exposure")
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=1e-6, frames="auto")
fit_items, heldout = seeded_split(problem.n_items, 0.2, SEED % 1000)
effects = frozenset({"exposure_overlap", "detection_threshold", "integration_offset"})
specs = problem.param_specs(effects)
starts = {
    "first fit's basin": problem.fit(effects, fit_items).params,
    "four-effect fit's basin": {
        "row_time_s": 17.18e-6,
        "integration_offset_s": 90.58e-6,
        "threshold_s": 44.24e-6,
    },
}
for name, start in starts.items():
    squared, params = problem.fit_from(effects, specs, fit_items, FRAMES, start)
    error = problem.predict_fit(Fit(effects, params, {"frames": FRAMES}), heldout) - problem.rows[heldout]
    values = ", ".join(f"{k} {v * 1e6:.2f} us" for k, v in params.items())
    print(
        f"{name}: {values}; fit squared error {squared:.0f} rows^2, held-out RMSE {np.sqrt(np.mean(error**2)):.2f} rows"
    )
