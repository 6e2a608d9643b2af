"""The held-out check of ``test_the_law_recovers_the_jitter_of_the_transform_that_drew_the_counts_and_predicts_its_
next_frames`` (200 draws of 10 fit and 10 held-out frames, ``counts_drawn_by_the_transform``) on a package from
before session 63's ``CountLaw``: how many held-out counts have no probability. From this checkout's root:
``PYTHONPATH=OLD_CHECKOUT python docs/bench/session63/held_out_probe.py`` (the draws come from this checkout's
tests, the law from the package on ``PYTHONPATH``)."""

import sys

import numpy as np
import torch

sys.path[1:1] = ["tests", "tests/calibration"]
from test_truncation_frames import HEIGHT, counts_drawn_by_the_transform  # noqa: E402

from lerobot_phantom.calibration.core import Fit  # noqa: E402
from lerobot_phantom.calibration.frame_models.common import Pair  # noqa: E402
from lerobot_phantom.calibration.frame_models.em_truncation import TruncationFrames, count_law  # noqa: E402

blank = torch.zeros(3, HEIGHT, 1)
unexplained = 0
for seed in range(200):
    intensity, counts = counts_drawn_by_the_transform(seed)
    low, high, jitter = count_law(counts[:10], np.full(10, HEIGHT), intensity[:10].double().numpy())
    held_out = TruncationFrames(
        [Pair(str(k), blank, blank, None, float(intensity[k])) for k in range(10, 20)], 0
    )
    fit = Fit(
        frozenset(),
        {"ratio_per_intensity": 0.5 * (low + high), "ratio_jitter": jitter},
        {"slope_range": [low, high]},
    )
    for k in range(10):
        predicted, _ = held_out.predicted_counts(fit, k)
        unexplained += counts[10 + k] not in predicted
print("held-out counts with no probability:", unexplained, "of 2000")
