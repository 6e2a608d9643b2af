"""Drawn camera 3808238891 (lit frames) at one condition of its held-out rows: the test's simulator against the
package's kernel, with the camera's blooming and read noise switched on and off, and the simulator's time step
(``dt``, 2 us in the test) at its own value and at 0.1 us. Run from a checkout, whose package and test simulator are
what is measured:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session43/noise_bloom.py SEED lit|interior \
        FREQUENCY_HZ DUTY EXPOSURE_US [FRAMES]
"""

import os
import sys
from pathlib import Path

import numpy as np
import torch

seed, frames = int(sys.argv[1]), sys.argv[2]
frequency, duty, exposure = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5]) * 1e-6
n_frames = int(sys.argv[6]) if len(sys.argv) > 6 else 600
os.environ["STRIPES_SEED"] = str(seed)  # the test module draws its seed at import
sys.path.insert(0, str(Path("tests/calibration").resolve()))
import test_stripes  # noqa: E402

from lerobot_phantom.transforms import physics  # noqa: E402

camera = test_stripes.draw_camera(np.random.default_rng([seed, 2, len(frames)]), frames)
print(
    f"camera: height {camera['height']}, row time {camera['row_time'] * 1e6:.2f} us, offset "
    f"{camera['offset'] * 1e6:.2f} us, rise {camera['rise'] * 1e6:.2f} us, blooming {camera['spread']} rows, "
    f"threshold {camera['threshold_grey'] / camera['gain'] * 1e6:.2f} us, read noise "
    f"{camera['read_noise'] / camera['gain'] * 1e6:.2f} us; condition {frequency:g} Hz, duty {duty:g}, "
    f"exposure {exposure * 1e6:g} us; {n_frames} frames per simulated mean"
)
for dt in (camera["dt"], 1e-7):
    for spread in sorted({0, camera["spread"]}):
        for noise in (0.0, camera["read_noise"]):
            variant = camera | {"spread": spread, "read_noise": noise, "dt": dt}
            (counts,) = test_stripes.simulate_stripe_counts(
                variant, [(frequency, duty, exposure)], np.random.default_rng([seed, 7]), n_frames
            )
            kernel = physics.rolling_shutter_rows_lit(
                torch.tensor([frequency]),
                torch.tensor([duty]),
                torch.tensor([exposure]),
                camera["row_time"],
                image_rows=camera["height"],
                integration_offset_s=camera["offset"],
                threshold_s=camera["threshold_grey"] / camera["gain"],
                spread_rows=spread,
                noise_s=noise / camera["gain"] if noise else None,
                frames=frames,
            ).item()
            mean = np.mean(counts) if counts else float("nan")
            print(
                f"dt {dt * 1e6:g} us, blooming {spread} rows, read noise {noise:g} grey: simulated {mean:.1f} rows "
                f"over {len(counts)} counted frames, kernel {kernel:.1f} rows"
            )
