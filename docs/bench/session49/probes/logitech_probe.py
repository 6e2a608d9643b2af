"""The Logitech stripe table's calibration (as test_logitech_stripes runs it): held-out, effects, parameters."""

import sys
import tempfile
from pathlib import Path

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

table = Path(sys.argv[1])
with tempfile.TemporaryDirectory() as out:
    r = calibrate(
        CalibrateConfig(
            attack="laser_color_strip", measured=str(table), out=out, image_height=720, exposure_unit_s=1e-4
        )
    )
e = r["extended"]
print(
    f"base {r['base']['heldout_rmse']:.4f} extended {e['heldout_rmse']:.4f} effects {sorted(e['effects'])} params {e['params']} frames {e['derived'].get('frames_averaged')}"
)
