"""The margin of ``test_the_demosaic_form_finds_the_simulators_tile_and_halves_the_residual_variance`` on camsim
seeds the suite's fresh draw may not give, single and banded lost lines: per seed, the tile fitted with ``bayer_demosaic`` and the registered
residual variance with it over the map's (the test requires RGGB and under 0.5).
Usage: ``PYTHONPATH=.:tests/calibration:tests python docs/bench/session75/tile_variance_ratio.py FIRST LAST``."""

import sys

import numpy as np
from test_em_colour_map_fit import lost_line_pairs

from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames

for lost_lines, colour_map in (("single", frozenset({"bayer_phase_flip"})), ("banded", frozenset())):
    for seed in range(int(sys.argv[1]), int(sys.argv[2]) + 1):
        pairs = lost_line_pairs(seed, lost_lines)
        problem, items = EMStripFrames(pairs, seed=0), np.arange(len(pairs))
        mapped = problem.fit(colour_map, items)
        demosaic = problem.fit(colour_map | {"bayer_demosaic"}, items)
        ratio = demosaic.extra["noise_variance"] / mapped.extra["noise_variance"]
        print(f"{lost_lines} seed {seed}: tile {demosaic.extra['pattern']}, variance ratio {ratio:.3f}")
