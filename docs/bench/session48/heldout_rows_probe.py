"""Where a drawn second camera's held-out error sits: ``lerobot-phantom-calibrate`` on ``test_stripes.py``'s table for
STRIPES_SEED (frame rule as given, the test's flags), then the held-out rows by their error under the written model,
each with its condition, its regime (window = exposure + the camera's offset against the laser period; pulse
on-time against the camera's threshold, in seconds of light), measured and predicted rows, and the prediction of the
full model fitted on the fit rows from the camera's own parameters (what the fit rows allow).

Usage: ``HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session48/heldout_rows_probe.py SEED lit|interior``
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")

import test_stripes as ts

from lerobot_phantom.calibration.core import Fit, fit_least_squares, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

seed, frames = int(sys.argv[1]), sys.argv[2]
style = "exposure" if frames == "interior" else "exposure_us"
with tempfile.TemporaryDirectory() as root:
    camera, report = ts.calibrate_drawn_camera(Path(root), seed, frames, style, calibration_seed=seed % 1000)
    problem = StripeProblem(
        Path(root) / "second_camera.csv",
        image_height=camera["height"],
        exposure_unit_s=1e-6 if style == "exposure" else None,
    )
print(ts.camera_summary(camera))
extended = report["extended"]
written = Fit(
    frozenset(extended["effects"]), extended["params"], {"frames": extended["derived"]["frames_averaged"]}
)
fit_items, held = seeded_split(problem.n_items, 0.2, seed % 1000)
full = frozenset({"exposure_overlap", "integration_offset", "detection_threshold", "detection_noise"})
truth = {
    "row_time_s": camera["row_time"],
    "integration_offset_s": camera["offset"] + 2 * camera["spread"] * camera["row_time"],
    "threshold_s": camera["threshold_grey"] / camera["gain"],
    "noise_s": camera["read_noise"] / camera["gain"],
}
target = torch.as_tensor(problem.rows[fit_items])
allowed = Fit(
    full,
    fit_least_squares(
        problem.param_specs(full), lambda p: problem.predict(full, p, fit_items, frames) - target, warm=truth
    ),
    {"frames": frames},
)
print(f"written {sorted(written.effects)} {written.params}: held-out {extended['heldout_rmse']:.2f} rows")
print(f"full model from the camera's parameters, on the fit rows: {allowed.params}")
predicted, best = problem.predict_fit(written, held), problem.predict_fit(allowed, held)
threshold = truth["threshold_s"]
for k in np.argsort(-np.abs(predicted - problem.rows[held])):
    i = held[k]
    period, on = 1.0 / problem.frequency_hz[i], problem.duty[i] / problem.frequency_hz[i]
    window = problem.exposure_s[i] + camera["offset"]
    print(
        f"{problem.item_label(int(i)):45s} window/period {window / period:6.3f} on/threshold {on / threshold:6.2f}"
        f" | measured {problem.rows[i]:7.1f} written {predicted[k]:7.1f} full-from-camera {best[k]:7.1f}"
    )
