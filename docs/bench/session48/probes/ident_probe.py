"""Session 48 scratch probe, run from a checkout's root with that checkout on PYTHONPATH (outputs beside it name
the commit). report.json's identification and selection for test_stripes.py's drawn camera: ``python ident_probe.py SEED [lit|interior]``"""

import json
import os
import sys
import tempfile
from pathlib import Path

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

frames = sys.argv[2] if len(sys.argv) > 2 else "interior"
style = "exposure" if frames == "interior" else "exposure_us"
with tempfile.TemporaryDirectory() as root:
    camera, report = ts.calibrate_drawn_camera(
        Path(root), ts.SEED, frames, style, calibration_seed=ts.SEED % 1000
    )
    print(ts.camera_summary(camera))
    print(
        "threshold_s truth",
        camera["threshold_grey"] / camera["gain"],
        "noise_s",
        camera["read_noise"] / camera["gain"],
    )
    for r in report["identification"]:
        print(json.dumps(r, default=str)[:900])
    print("written:", report["extended"]["effects"], report["extended"]["params"])
    print("held-out: base", report["base"]["heldout_rmse"], "written", report["extended"]["heldout_rmse"])
    print(json.dumps(report.get("selection", {}), default=str))
