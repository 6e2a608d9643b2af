"""Kernel (camera's own parameters) vs simulator on one condition of a drawn camera: 1222484455 interior, row 42."""

import os
import sys

import numpy as np
import torch

os.environ["STRIPES_SEED"] = "1222484455"
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

from lerobot_phantom.transforms import physics

seed, frames = int(sys.argv[1]), sys.argv[2]
f, d, e = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
cam = ts.draw_camera(np.random.default_rng([seed, 2, len(frames)]), frames)
counts = ts.simulate_stripe_counts(cam, [(f, d, e)], np.random.default_rng(5), 400)[0]
print("sim kept", len(counts), "mean", np.mean(counts), "hist", np.unique(counts, return_counts=True))
truth = dict(
    row_time_s=cam["row_time"],
    image_rows=cam["height"],
    integration_offset_s=cam["offset"],
    threshold_s=cam["threshold_grey"] / cam["gain"],
    spread_rows=cam["spread"],
    noise_s=cam["read_noise"] / cam["gain"],
)
for rule in ("all", "lit", "interior"):
    print(
        rule,
        float(
            physics.rolling_shutter_rows_lit(
                torch.tensor([f]), torch.tensor([d]), torch.tensor([e]), frames=rule, **truth
            )
        ),
    )
p = 1 / f / cam["row_time"]
w = (d / f + e + cam["offset"]) / cam["row_time"]
print("period rows", p, "width rows approx", w, "height", cam["height"])
