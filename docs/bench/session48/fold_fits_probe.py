"""The offset model's fits on each cross-validation fold of one drawn second camera (``test_stripes.py``'s draw for
STRIPES_SEED, interior frames; the split and folds of ``calibrate_drawn_camera``): each frame rule's own search, the
interior rule started at the camera's row time, and the rule the fit keeps; then the cross-validated score of the
overlap and of the offset model as selection computes it (each fold started from the overlap's fold fit).

Usage (from a checkout's root; run it at two commits to compare): ``HF_HUB_OFFLINE=1 PYTHONPATH=. python
docs/bench/session48/fold_fits_probe.py 3503845322``.
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")

import test_stripes as ts

from lerobot_phantom.calibration.core import Fit, cross_validated, kfold, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

seed = int(sys.argv[1])
with tempfile.TemporaryDirectory() as root:
    table = Path(root) / "table.csv"
    camera = ts.drawn_camera_table(table, seed, "interior", "exposure")
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=1e-6)
print(ts.camera_summary(camera))
fit_items, _ = seeded_split(problem.n_items, 0.2, seed % 1000)
splits = kfold(fit_items, 4, seed % 1000 + 1, 2500)
overlap = frozenset({"exposure_overlap"})
offset = overlap | {"integration_offset"}


def rmse(fit: Fit, items: np.ndarray) -> float:
    return float(np.sqrt(np.mean(problem.residual(fit, items) ** 2)))


def show(name: str, fit: Fit, items: np.ndarray) -> str:
    return f"{name} {fit.params['row_time_s'] * 1e6:5.2f} us {rmse(fit, items):6.2f} rows"


for k, (train, _) in enumerate(splits):
    interior = problem.fit_rules(offset, train, None, ("interior",))
    started = problem.fit_rules(
        offset, train, Fit(offset, {"row_time_s": camera["row_time"]}, {"frames": "interior"}), ("interior",)
    )
    lit = problem.fit_rules(offset, train, None, ("lit",))
    kept = problem.fit(offset, train)
    print(
        f"fold {k}: {show('interior search', interior, train)} | {show('interior from the camera', started, train)}"
        f" | {show('lit', lit, train)} | kept: {kept.extra['frames']}, {show('', kept, train)}"
    )
score_overlap, overlap_fits, _ = cross_validated(problem, overlap, splits, None)
score_offset, offset_fits, _ = cross_validated(problem, offset, splits, overlap_fits)
print(
    f"cross-validated mean per-item error: overlap {score_overlap:.2f} rows, offset {score_offset:.2f} rows"
)
print("offset fold fits:", [(round(f.params["row_time_s"] * 1e6, 2), f.extra["frames"]) for f in offset_fits])
