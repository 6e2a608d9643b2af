"""Whether the second-camera test's drawn tables are offered phase_drift (and so drift_from_entry): rows per recording
(a laser frequency and exposure setting) of each 60-row table, from the test's own draw of camera and conditions,
without simulating frames. The figure counts the drawn conditions; the test then drops rows whose simulated frames
were all discarded, which this script does not simulate.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session33/second_camera_drift_offer.py SEED [SEED ...]``
"""

import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.stripes import MIN_ROWS_PER_RECORDING

sys.path.insert(0, str(Path("tests/calibration").resolve()))
import os

os.environ.setdefault("STRIPES_SEED", "0")
import test_stripes

for seed in map(int, sys.argv[1:]):
    for frames in ("lit", "interior"):
        rng = np.random.default_rng([seed, 2, len(frames)])
        camera = test_stripes.draw_camera(rng, frames)
        grid = [
            (f, d, e)
            for f in camera["frequencies"]
            for d in test_stripes.DUTIES
            for e in camera["exposures_us"]
        ]
        chosen = [grid[i] for i in rng.choice(len(grid), 60, replace=False)]
        recordings = len({(f, e) for f, _, e in chosen})
        per = 60 / recordings
        print(
            f"{seed:>10} {frames:<8} {recordings} recordings, {per:.2f} rows each: offered {per >= MIN_ROWS_PER_RECORDING}"
        )
