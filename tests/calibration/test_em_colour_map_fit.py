"""EM colour strip frame model: the colour-map fit must not stay at a start where the clamped map saturates; the
demosaic form (``bayer_demosaic``) finds the colour-filter tile of frames an independent simulator mis-decodes
from its raw mosaic, and loses to the map where the map made the frames."""

from __future__ import annotations

import os

import camsim as cs
import numpy as np
import pytest
import torch

from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames
from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.em_color_strip import EMColorStrip, row_weights_of


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


def lost_line_pairs(seed: int, lost_lines: str = "single") -> list[Pair]:
    """camsim's lost lines (one per frame, or bands): its RGGB raw lines moved up by one, then its own bilinear
    demosaic, tone curve, noise and JPEG (not the package's forms)."""
    frames = cs.em_strip_pairs(np.random.default_rng(seed), cs.Camera(), 8, lost_lines=lost_lines)
    as_tensor = lambda image: torch.from_numpy(image.transpose(2, 0, 1) / 255.0)  # noqa: E731
    return [
        Pair(f"pair_{i}", as_tensor(f.clean), as_tensor(f.attacked), None, f.intensity)
        for i, f in enumerate(frames)
    ]


@pytest.mark.parametrize(
    "lost_lines, colour_map", [("single", frozenset({"bayer_phase_flip"})), ("banded", frozenset())]
)
def test_the_demosaic_form_finds_the_simulators_tile_and_halves_the_residual_variance(lost_lines, colour_map):
    seed = int(os.environ["CAMSIM_SEED"])  # fresh per run (tests/conftest.py)
    pairs = lost_line_pairs(seed, lost_lines)
    problem, items = EMStripFrames(pairs, seed=0), np.arange(len(pairs))
    mapped = problem.fit(colour_map, items)
    demosaic = problem.fit(colour_map | {"bayer_demosaic"}, items)
    assert demosaic.extra["pattern"] == "RGGB", f"replay with CAMSIM_SEED={seed}"
    assert problem.transform_kwargs(demosaic)["demosaic_pattern"] == "RGGB"
    ratio = demosaic.extra["noise_variance"] / mapped.extra["noise_variance"]
    assert ratio < 0.5, f"residual variance ratio {ratio:.3f}; replay with CAMSIM_SEED={seed}"


def test_the_demosaic_form_loses_to_the_map_on_frames_the_map_made():
    pairs = bright_flipped_pairs(1.2, 0.05)
    problem, items = EMStripFrames(pairs, seed=0), np.arange(len(pairs))
    colour_map = problem.fit(frozenset({"bayer_phase_flip"}), items)
    demosaic = problem.fit(frozenset({"bayer_phase_flip", "bayer_demosaic"}), items)
    assert demosaic.extra["noise_variance"] > 2 * colour_map.extra["noise_variance"]


@pytest.mark.parametrize(
    "lost_lines, effects",
    [
        ("single", frozenset({"bayer_phase_flip", "bayer_demosaic"})),
        ("banded", frozenset({"bayer_demosaic"})),
    ],
)
def test_the_placement_search_scores_each_frame_as_the_prediction_it_registers(lost_lines, effects):
    """The search's per-row costs (eight neighbourhoods per row) add up to the squared error of the frame
    ``predict_registered`` builds with ``physics.em_demosaic_rows``, band edges and the rows beside them included."""
    pairs = lost_line_pairs(3, lost_lines)
    problem = EMStripFrames(pairs, seed=0)
    fit = problem.fit(effects, np.arange(len(pairs)))
    for index, pair in enumerate(pairs):
        predicted = problem.predict_registered(fit, index)
        assert problem.registered_sse(fit, index) == pytest.approx(
            float(((predicted - pair.attacked) ** 2).sum())
        )


def test_the_papers_bands_hand_the_attack_their_fitted_colour_map():
    """Periodic bands (the base model) whose rows show the colour map 1.2, 0.05: the base fit recovers it, and
    calibrated.json gives it to the attack, whose bands then show it (until session 88 the base handed the attack no
    options, and the paper's bands ignored a colour map: the paper's 2.5, 50 / 255 whatever was measured)."""
    rng = np.random.default_rng(11)
    pairs = []
    for i in range(6):
        clean = torch.from_numpy(rng.uniform(0.2, 0.6, (3, 24, 32)))
        band = physics.em_color_map(clean.unsqueeze(0), 1.2, 0.05)[0]
        rows = (np.arange(24) + int(rng.integers(0, 8))) % 8 < 4  # a period of 8 rows, its phase per frame
        attacked = torch.where(torch.from_numpy(rows)[None, :, None], band, clean)
        pairs.append(Pair(f"pair_{i}", clean, attacked, None, 1.0))
    problem = EMStripFrames(pairs, seed=0)
    fit = problem.fit(frozenset(), np.arange(len(pairs)))
    options = problem.transform_kwargs(fit)
    assert set(options) == {"gain", "offset"}
    assert options["gain"] == pytest.approx(1.2, abs=0.02) and options["offset"] == pytest.approx(
        0.05, abs=0.01
    )
    attack = EMColorStrip("strong", **options)
    clean = pairs[0].clean.unsqueeze(0).float()
    params = attack.sample_params(1, 24, 32)
    weights = row_weights_of(clean, params)[0]
    mis_decoded = weights == 1
    assert 0 < int(mis_decoded.sum()) < 24
    expected = physics.em_color_map(clean, options["gain"], options["offset"])[0].clamp(0, 1)
    torch.testing.assert_close(
        attack.apply_params(clean, params)[0][:, mis_decoded], expected[:, mis_decoded]
    )
