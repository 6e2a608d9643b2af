"""The margin of ``test_the_demosaic_form_finds_the_simulators_tile_and_halves_the_residual_variance`` on camsim
seeds the suite's fresh draw may not give: per seed, the tile fitted with ``bayer_demosaic`` and the registered
residual variance with it over the map's (the test requires RGGB and under 0.5).
Usage: ``PYTHONPATH=.:tests/calibration:tests python docs/bench/session75/tile_variance_ratio.py FIRST LAST``."""

import sys

import numpy as np
from test_em_colour_map_fit import lost_line_pairs

from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames

for seed in range(int(sys.argv[1]), int(sys.argv[2]) + 1):
    pairs = lost_line_pairs(seed)
    problem, items = EMStripFrames(pairs, seed=0), np.arange(len(pairs))
    colour_map = problem.fit(frozenset({"bayer_phase_flip"}), items)
    demosaic = problem.fit(frozenset({"bayer_phase_flip", "bayer_demosaic"}), items)
    ratio = demosaic.extra["noise_variance"] / colour_map.extra["noise_variance"]
    print(f"seed {seed}: tile {demosaic.extra['pattern']}, variance ratio {ratio:.3f}")
