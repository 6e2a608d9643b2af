import math
import os
import pickle

import numpy as np
import pytest
import torch
from reference_optical import laser_color_strip_reference

from lerobot_phantom.transforms.laser_color_strip import (
    PAPER_COLOR_FRACTIONS,
    STRENGTH_LEVELS,
    LaserColorStrip,
    band_rows,
    laser_color_strip,
    strip_profile,
)

os.environ.setdefault("HF_HUB_OFFLINE", "1")


def _random_uint8(shape, seed):
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


def _hwc(chw: torch.Tensor) -> np.ndarray:
    return chw.permute(1, 2, 0).numpy()


@pytest.mark.parametrize("size", [(24, 32), (31, 17), (5, 3)])
@pytest.mark.parametrize("level", ["weak", "medium", "strong"])
def test_matches_paper_reference(size, level):
    img = _random_uint8((3, *size), seed=size[1] + len(level))
    attack = LaserColorStrip(level)
    params = attack.sample_params(1, *size)
    strength = float(params["strength"][0])
    assert strength == pytest.approx(
        dict(zip(("weak", "medium", "strong"), STRENGTH_LEVELS[1:], strict=True))[level]
    )
    expected = laser_color_strip_reference(_hwc(img), strength, PAPER_COLOR_FRACTIONS)
    fast = attack.apply_params(img, params)
    assert np.abs(_hwc(fast).astype(int) - expected.astype(int)).max() <= 1
    functional = laser_color_strip(img, strength, PAPER_COLOR_FRACTIONS)
    assert np.abs(_hwc(functional).astype(int) - expected.astype(int)).max() <= 1


def test_only_the_band_rows_change_and_red_dominates():
    img = torch.full((3, 30, 40), 0.2)
    out = LaserColorStrip("weak")(img)
    start, end = band_rows(30)
    assert (start, end) == (10, 20)
    assert torch.equal(out[:, :start], img[:, :start]) and torch.equal(out[:, end:], img[:, end:])
    added = out[:, start:end] - img[:, start:end]
    assert bool((added[0] >= added[1]).all()) and float(added[0].mean()) > 0.1


def test_gaussian_centre_sits_below_the_band_as_in_the_paper_code():
    profile = strip_profile(60, 80)
    column = profile[:, 40]
    assert bool((column[1:] > column[:-1]).all())  # brightening towards the band's lower edge
    assert int(profile[-1].argmax()) == 40  # centred horizontally at w / 2


def test_peak_gain_does_not_depend_on_image_size():
    # S*h*w cancels the Gaussian's normaliser: the band's peak is 4/pi * exp(-a/2) with a ~ 1/9 whatever the size
    small, large = strip_profile(30, 40), strip_profile(300, 400)
    assert float(small.max()) == pytest.approx(float(large.max()), rel=0.05)
    assert float(large.max()) < 4.0 / np.pi


def test_per_sample_strength_and_colour_fractions():
    img = torch.zeros(2, 3, 12, 12)
    out = laser_color_strip(
        img, torch.tensor([0.0, 2500.0]), torch.tensor([[0.6, 0.1, 0.1], [0.0, 0.0, 1.0]])
    )
    assert torch.equal(out[0], img[0])
    assert float(out[1, 2].max()) == 1.0 and float(out[1, :2].max()) == 0.0


def test_profile_is_cached_per_size_and_dropped_on_pickle():
    attack = LaserColorStrip()
    assert attack.profile(20, 30) is attack.profile(20, 30)
    clone = pickle.loads(pickle.dumps(attack))
    assert clone._cache == {}
    img = _random_uint8((3, 20, 30), seed=0)
    assert torch.equal(clone(img), attack(img))


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="color_fractions"):
        LaserColorStrip(color_fractions=(0.6, 0.1))
    with pytest.raises(ValueError, match="levels"):
        LaserColorStrip(levels=(0, 1500, 500, 2500))
    with pytest.raises(ValueError, match="strength"):
        laser_color_strip(torch.zeros(3, 4, 4), -1.0)


@pytest.mark.parametrize("intensity", ["weak", "strong", "random", (0.0, 1.0)])
@pytest.mark.parametrize("channels", [3, 4, 1])
def test_uint8_kernel_is_within_one_grey_level_of_the_float_path(intensity, channels):
    """uint8 images are attacked in uint8 (a saturating add of the rounded increment), no float round trip."""
    imgs = _random_uint8((4, channels, 30, 26), seed=channels)
    attack = LaserColorStrip(intensity)
    params = attack.sample_params(4, 30, 26, generator=torch.Generator().manual_seed(1))
    out = attack.apply_params(imgs, params)
    out_float = attack.apply_params(imgs.float() / 255, params)
    assert out.dtype == torch.uint8 and out.shape == imgs.shape
    assert float((out_float.double() * 255 - out.double()).abs().max()) <= 1.0
    start, _ = band_rows(30)
    torch.testing.assert_close(out[..., :start, :], imgs[..., :start, :], atol=0, rtol=0)
    assert not torch.equal(out, imgs)


def test_random_draws_the_authors_uniform_strength():
    """ "random" = the authors' training: S ~ U(500, 2500) grey-level units."""
    params = LaserColorStrip("random").sample_params(4000, 64, 64, generator=torch.Generator().manual_seed(0))
    strength = params["strength"].double()
    assert float(strength.min()) >= 500 - 1e-3 and float(strength.max()) <= 2500 + 1e-3
    for quantile in (0.25, 0.5, 0.75):
        assert float((strength < 500 + 2000 * quantile).double().mean()) == pytest.approx(quantile, abs=0.03)


def _rolling_shutter(gamma):
    # one pulse a frame lighting about a fifth of the rows, at pulse phase 0 (no generator), adding 0.05 of white
    return LaserColorStrip(
        "weak",
        levels=(0.0, 0.05 * 255 * math.pi / 4, 0.1 * 255 * math.pi / 4, 0.15 * 255 * math.pi / 4),
        model="rolling_shutter",
        frequency_hz=0.5,
        duty=0.1,
        exposure_s=0.05,
        row_time_s=1.0 / 48,
        frame_rows=48,
        gamma=gamma,
    )


def test_rolling_shutter_gamma_adds_light_before_the_tone_curve():
    grey = torch.linspace(0.05, 0.95, 32).expand(3, 48, 32).contiguous()  # dark columns left, bright right
    encoded = _rolling_shutter(None)(grey) - grey
    linear = _rolling_shutter(2.2)(grey) - grey
    lit = encoded[0].amax(dim=1) > 0
    assert 0 < int(lit.sum()) < 48
    # unlit rows are untouched either way
    assert torch.allclose(linear[:, ~lit], torch.zeros_like(linear[:, ~lit]), atol=1e-6)
    # added to encoded values every column gains the same; added in linear light a dark surface gains more
    # grey levels than a bright one (the power law's slope falls with the value)
    row = int(torch.nonzero(lit)[0])
    assert torch.allclose(encoded[0, row], encoded[0, row, :1].expand(32), atol=1e-6)
    assert bool((linear[0, row, :-1] > linear[0, row, 1:]).all())
    # a power law of exponent 1 is the encoded composition
    assert torch.allclose(_rolling_shutter(1.0)(grey), _rolling_shutter(None)(grey), atol=1e-6)


def test_gamma_needs_the_rolling_shutter_model():
    with pytest.raises(ValueError, match="rolling_shutter"):
        LaserColorStrip(gamma=2.2)
    with pytest.raises(ValueError, match="gamma > 0"):
        LaserColorStrip(model="rolling_shutter", gamma=0.0)
    assert pickle.loads(pickle.dumps(_rolling_shutter(2.2))).tone == 2.2
