"""``docs/bench/session49/probes/logitech_probe.py`` with ``StripeProblem.joint_effects`` set, and the CPU time.

python logitech_joint.py LOGITECH_TABLE JOINT
"""

import sys
import tempfile
import time

import lerobot_phantom
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.stripes import StripeProblem

StripeProblem.joint_effects = int(sys.argv[2])
began = time.process_time()
with tempfile.TemporaryDirectory() as out:
    config = CalibrateConfig(
        attack="laser_color_strip", measured=sys.argv[1], out=out, image_height=720, exposure_unit_s=1e-4
    )
    report = calibrate(config)
extended = report["extended"]
print(lerobot_phantom.__file__, "joint_effects", StripeProblem.joint_effects)
print(
    f"base {report['base']['heldout_rmse']:.4f} extended {extended['heldout_rmse']:.4f} "
    f"effects {sorted(extended['effects'])} params {extended['params']} "
    f"frames {extended['derived'].get('frames_averaged')} cpu {time.process_time() - began:.0f} s"
)
