"""Selection steps and identification of a drawn second camera (test_stripes' table for STRIPES_SEED)."""

import json
import os
import sys
import tempfile
from pathlib import Path

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

seed, frames = int(sys.argv[1]), sys.argv[2]
style = "exposure" if frames == "interior" else "exposure_us"
with tempfile.TemporaryDirectory() as root:
    camera, report = ts.calibrate_drawn_camera(Path(root), seed, frames, style, calibration_seed=seed % 1000)
print(ts.camera_summary(camera))
print("truth threshold", camera["threshold_grey"] / camera["gain"], "offset", camera["offset"])
for step in report["selection"]["steps"]:
    print(json.dumps(step, default=str)[:1500])
print("withdrawn", report["selection"].get("withdrawn"))
for r in report["identification"]:
    print(
        r["effect"],
        r["identified"],
        r.get("reasons"),
        json.dumps(r.get("validation_ratio"), default=str)[:300],
    )
print(
    "extended",
    report["extended"]["effects"],
    report["extended"]["params"],
    report["extended"]["heldout_rmse"],
)
