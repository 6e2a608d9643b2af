"""The SLAP stop sign's fitted reflectance floor by this checkout's package (run from a worktree with PYTHONPATH=.).

Usage: python docs/bench/session82/stop_sign_floor.py MEASURED_DIR (``../shared/measured``)"""

import sys
import tempfile
from pathlib import Path

import lerobot_phantom
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

table = Path(sys.argv[1]) / "projection" / "slap_stop_sign_triples.csv"
with tempfile.TemporaryDirectory() as scratch:
    report = calibrate(CalibrateConfig(attack="light_projection", measured=str(table), out=f"{scratch}/out"))
print(lerobot_phantom.__file__, repr(report["extended"]["params"].get("reflectance_floor")))
