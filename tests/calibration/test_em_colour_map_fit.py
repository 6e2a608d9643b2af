"""EM colour strip frame model: the colour-map fit must not stay at a start where the clamped map saturates."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames
from lerobot_phantom.transforms import physics


def bright_flipped_pairs(gain: float, offset: float, seed: int = 7) -> list[Pair]:
    """Bright frames (green 0.45-0.9, where the paper's gain 2.5 clamps every mis-decoded pixel to white) whose
    rows from a random row on show the colour map ``gain``, ``offset``."""
    rng = np.random.default_rng(seed)
    pairs = []
    for i in range(6):
        clean = torch.from_numpy(rng.uniform(0.45, 0.9, (3, 24, 32)))
        flip_row = int(rng.integers(4, 20))
        wrong = physics.em_color_map(clean.unsqueeze(0), gain, offset)[0]
        attacked = clean.clone()
        attacked[:, flip_row:] = wrong[:, flip_row:]
        pairs.append(Pair(f"pair_{i}", clean, attacked, None, 1.0))
    return pairs


@pytest.mark.parametrize("gain, offset", [(1.0, 0.0), (1.2, 0.05)])
def test_colour_map_is_recovered_where_the_papers_map_saturates(gain, offset):
    pairs = bright_flipped_pairs(gain, offset)
    fit = EMStripFrames(pairs, seed=0).fit(frozenset({"bayer_phase_flip"}), np.arange(len(pairs)))
    assert fit.params["gain"] == pytest.approx(gain, abs=0.02)
    assert fit.params["offset"] == pytest.approx(offset, abs=0.01)
