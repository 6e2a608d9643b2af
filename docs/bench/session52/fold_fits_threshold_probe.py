"""The threshold model's fits on each selection fold of one drawn second camera (``test_stripes.py``'s draw for
STRIPES_SEED and frames; the split and folds ``calibrate_drawn_camera`` makes): per fold, the overlap and the
overlap + threshold (+ offset) as selection fits them (started from the overlap's fold fit), the same models started
from the camera's own values, and each one's training error and the mean absolute error on the rows it validates.
Then the same on all fit rows against the held-out rows.

Usage (from a checkout's root): ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python
docs/bench/session52/fold_fits_threshold_probe.py 531200696 lit``.
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

from lerobot_phantom.calibration.core import Fit, kfold, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

seed, frames = int(sys.argv[1]), sys.argv[2]
style = "exposure" if frames == "interior" else "exposure_us"
with tempfile.TemporaryDirectory() as root:
    table = Path(root) / "table.csv"
    camera = ts.drawn_camera_table(table, seed, frames, style)
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=1e-6)
print(ts.camera_summary(camera))
truth = {
    "row_time_s": camera["row_time"],
    "integration_offset_s": camera["offset"],
    "threshold_s": camera["threshold_grey"] / camera["gain"],
}
print({k: round(v * 1e6, 2) for k, v in truth.items()}, "us")
fit_items, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
splits = kfold(fit_items, 4, seed % 1000 + 1, 2500)
overlap = frozenset({"exposure_overlap"})
models = {
    "overlap": overlap,
    "+threshold": overlap | {"detection_threshold"},
    "+offset": overlap | {"integration_offset"},
    "+threshold+offset": overlap | {"detection_threshold", "integration_offset"},
}


def mae(fit: Fit, items: np.ndarray) -> float:
    return float(np.mean(np.abs(problem.residual(fit, items))))


def rmse(fit: Fit, items: np.ndarray) -> float:
    return float(np.sqrt(np.mean(problem.residual(fit, items) ** 2)))


def show(fit: Fit) -> str:
    return (
        " ".join(f"{k[:-2]}={v * 1e6:.2f}us" for k, v in fit.params.items()) + f" [{fit.extra.get('frames')}]"
    )


def describe(items: np.ndarray) -> str:
    on = problem.duty[items] / problem.frequency_hz[items]
    return "; ".join(
        f"{problem.frequency_hz[i]:g}Hz exp{problem.exposure_setting[i]:g} duty{100 * problem.duty[i]:g}% "
        f"on={o * 1e6:.1f}us rows={problem.rows[i]:.1f}"
        for i, o in zip(items, on, strict=True)
    )


blocks = [(f"fold {k}", train, val) for k, (train, val) in enumerate(splits)] + [
    ("all fit", fit_items, heldout)
]
totals = {name: [] for name in models} | {
    name + " (camera start)": [] for name in models if name != "overlap"
}
for label, train, val in blocks:
    print(f"== {label}: {len(train)} train, {len(val)} validated")
    parent = problem.fit(overlap, train)
    for name, effects in models.items():
        fit = parent if name == "overlap" else problem.fit(effects, train, parent)
        print(f"  {name:20s} train rmse {rmse(fit, train):7.2f} | val mae {mae(fit, val):7.2f} | {show(fit)}")
        if label != "all fit":
            totals[name].append(np.abs(problem.residual(fit, val)))
        if name == "overlap":
            continue
        start = Fit(
            effects, {k: v for k, v in truth.items() if k in fit.params}, {"frames": fit.extra["frames"]}
        )
        from_truth = problem.fit(effects, train, start)
        print(
            f"  {name + ' (camera)':20s} train rmse {rmse(from_truth, train):7.2f} | val mae "
            f"{mae(from_truth, val):7.2f} | {show(from_truth)}"
        )
        if label != "all fit":
            totals[name + " (camera start)"].append(np.abs(problem.residual(from_truth, val)))
    worst = val[
        np.argsort(-np.abs(problem.residual(problem.fit(models["+threshold"], train, parent), val)))[:3]
    ]
    print("  worst validated rows under +threshold:", describe(worst))
print("== cross-validated mean per-row error")
for name, parts in totals.items():
    print(f"  {name:32s} {np.mean(np.concatenate(parts)):.2f}")
