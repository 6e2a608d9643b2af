"""Calibrate light projection frame pairs with selection scoring groups of up to N new effects (the scratch probe
behind ``filmic_draw_725596845.txt``). Usage: ``PYTHONPATH=. python docs/bench/session76/groups_of_four_probe.py
PAIRS_DIR OUT_DIR SEED N``."""

import sys

import lerobot_phantom.calibration.frame_models.light_projection as frames
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

frames.ProjectionFrames.joint_effects = int(sys.argv[4])
pairs, out, seed = sys.argv[1], sys.argv[2], int(sys.argv[3])
r = calibrate(CalibrateConfig(attack="light_projection", measured=pairs, out=out, seed=seed % 2**31))
print(
    r["extended"]["effects"],
    round(r["extended"]["heldout_rmse"], 3),
    {k: round(v, 3) for k, v in r["extended"]["params"].items() if not k.startswith("crosstalk")},
)
