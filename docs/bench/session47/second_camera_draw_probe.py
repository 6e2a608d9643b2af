"""One drawn second camera of ``tests/calibration/test_stripes.py`` (interior frames, exposure without a unit): the
camera, the table, and the report's model, held-out error and structure summary (which names an outlying row).

Usage (from a checkout's root): ``HF_HUB_OFFLINE=1 python3 docs/bench/session47/second_camera_draw_probe.py
STRIPES_SEED``.
"""

import os
import sys
import tempfile
from pathlib import Path

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")

import pandas as pd
import test_stripes as ts

with tempfile.TemporaryDirectory() as root:
    camera, report = ts.calibrate_drawn_camera(
        Path(root), ts.SEED, "interior", "exposure", calibration_seed=ts.SEED % 1000
    )
    print(ts.camera_summary(camera))
    print(pd.read_csv(Path(root) / "second_camera.csv").to_string())
    print("written model:", report["extended"]["effects"], report["extended"]["params"])
    print(
        "held-out rmse: base", report["base"]["heldout_rmse"], "written", report["extended"]["heldout_rmse"]
    )
    print(report["unexplained_structure"]["summary"])
