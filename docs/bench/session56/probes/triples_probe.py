"""Selection on a drawn second camera (test_stripes' table) with ``StripeProblem.joint_effects`` set: the steps,
withdrawals, identification and the written model, and the process's CPU time.

    python triples_probe.py SEED FRAMES PULSES JOINT [CALIBRATION_SEED]

run from the root of the checkout whose package is tested (FRAMES: lit or interior; PULSES: mean or sampled, as
``test_stripes.drawn_camera_table``; JOINT: the largest group of new effects a step scores; CALIBRATION_SEED defaults
to SEED % 1000, as ``docs/bench/second_camera_sweep.py`` calibrates; sampled pulses take 10 bootstrap draws, as
their test does).
"""

import os
import sys
import tempfile
import time
from pathlib import Path

seed, frames, pulses, joint = int(sys.argv[1]), sys.argv[2], sys.argv[3], int(sys.argv[4])
calibration_seed = int(sys.argv[5]) if len(sys.argv) > 5 else seed % 1000
os.environ["STRIPES_SEED"] = str(seed)
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts  # noqa: E402

import lerobot_phantom  # noqa: E402
from lerobot_phantom.calibration.stripes import StripeProblem  # noqa: E402

StripeProblem.joint_effects = joint
print(lerobot_phantom.__file__, "joint_effects", StripeProblem.joint_effects)
style = "exposure" if frames == "interior" else "exposure_us"
began = time.process_time()
with tempfile.TemporaryDirectory() as root:
    options = {"bootstrap": 10} if pulses == "sampled" else {}
    camera, report = ts.calibrate_drawn_camera(
        Path(root), seed, frames, style, calibration_seed=calibration_seed, pulses=pulses, **options
    )
for step in report["selection"]["steps"]:
    tried = {k: round(v, 3) for k, v in (step.get("tried") or {}).items()}
    print(step["effects"], round(step["validation_error"], 3), tried)
print("withdrawn", report["selection"].get("withdrawn"))
for result in report["identification"]:
    print(" ", result["effect"], result["identified"], result.get("reasons"))
print(
    "extended",
    sorted(report["extended"]["effects"]),
    f"held-out {report['extended']['heldout_rmse']:.3f}",
    f"cpu {time.process_time() - began:.0f} s",
)
