"""The SLAP stop sign's fitted reflectance floor by this checkout's package (run from a worktree with PYTHONPATH=.)."""

import tempfile

import lerobot_phantom
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

with tempfile.TemporaryDirectory() as d:
    r = calibrate(
        CalibrateConfig(
            attack="light_projection",
            measured="/work/shared/measured/projection/slap_stop_sign_triples.csv",
            out=d + "/o",
        )
    )
print(lerobot_phantom.__file__, repr(r["extended"]["params"].get("reflectance_floor")))
