import itertools
import os
import pickle

import numpy as np
import pytest
import torch
from reference_em_blur import em_color_strip_reference

from lerobot_phantom.transforms import em_color_strip as em_color_strip_module
from lerobot_phantom.transforms.em_color_strip import (
    EMColorStrip,
    em_color_strip,
    stripe_params_for,
    stripe_row_weights,
)
from lerobot_phantom.transforms.intensity import LEVELS

os.environ.setdefault("HF_HUB_OFFLINE", "1")


def _random_uint8(shape, seed):
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


def _reference(img: torch.Tensor, num_stripes: int, **kwargs) -> torch.Tensor:
    out = em_color_strip_reference(img.permute(1, 2, 0).numpy(), num_stripes, **kwargs)
    return torch.from_numpy(np.ascontiguousarray(out)).permute(2, 0, 1)


def _mad(a: torch.Tensor, b: torch.Tensor) -> float:
    return (a.double() - b.double()).abs().mean().item()


@pytest.mark.parametrize("shape", [(3, 17, 23), (3, 64, 40), (3, 7, 5), (3, 255, 3)])
@pytest.mark.parametrize("num_stripes", [8, 12, 16, 5])
def test_matches_reference_within_one_grey_level(shape, num_stripes):
    img = _random_uint8(shape, seed=shape[1] + num_stripes)
    expected = _reference(img, num_stripes)
    out = em_color_strip(img, num_stripes)
    # uint8 is computed in integers: the paper's int() formula exactly
    torch.testing.assert_close(out, expected, atol=0, rtol=0)
    assert not torch.equal(out, img)
    # float keeps continuous values: within one grey level of the paper's truncation
    out_float = em_color_strip(img.float() / 255, num_stripes)
    assert float((out_float * 255 - expected.float()).abs().max()) <= 1.0


@pytest.mark.parametrize("level", ["weak", "medium", "strong"])
def test_levels_are_the_papers_stripe_counts(level):
    num_stripes = {"weak": 8, "medium": 12, "strong": 16}[level]
    img = _random_uint8((2, 3, 48, 30), seed=1)
    attack = EMColorStrip(level)
    torch.testing.assert_close(attack(img), em_color_strip(img, num_stripes), atol=0, rtol=0)
    assert int((attack(img)[0].int() - _reference(img[0], num_stripes).int()).abs().max()) <= 1


def test_uint8_overflow_of_the_paper_is_fixed():
    img = torch.zeros(3, 16, 4, dtype=torch.uint8)
    img[0], img[1], img[2] = 200, 10, 100  # R + B = 300 > 255
    paper = _reference(img, 8, paper_uint8_sum=True)
    fixed = _reference(img, 8)
    # row 0 is corrupted: the paper computes (300 mod 256) / 2 - 50 = -28 -> 0, the formula gives 150 - 50 = 100
    assert int(paper[1, 0, 0]) == 0
    assert int(fixed[1, 0, 0]) == 100
    ours = em_color_strip(img, 8)
    assert int(ours[1, 0, 0]) == 100
    assert int(ours[0, 0, 0]) == 25 and int(ours[2, 0, 0]) == 25  # 2.5 * G
    torch.testing.assert_close(ours, fixed, atol=1, rtol=0)


@pytest.mark.parametrize("height", [256, 96, 17, 33, 2])
def test_row_weights_select_exactly_the_papers_bands(height):
    img = torch.full(
        (3, height, 2), 100, dtype=torch.uint8
    )  # every corrupted pixel changes (G' = 50, R' = 250)
    stripes = torch.tensor([8.0, 12.0, 16.0], dtype=torch.float64)
    weights = stripe_row_weights(height, stripes, torch.ones(3, dtype=torch.float64))
    for i, n in enumerate((8, 12, 16)):
        changed_rows = (_reference(img, n) != img).any(dim=0).any(dim=1)
        torch.testing.assert_close(weights[i] == 1, changed_rows)
        assert ((weights[i] == 0) | (weights[i] == 1)).all()


def test_small_images_do_not_crash_and_one_row_is_identity():
    for shape in [(3, 1, 1), (3, 1, 9), (3, 3, 3), (1, 5, 2)]:
        img = _random_uint8(shape, 2)
        out = EMColorStrip("strong")(img)
        assert out.shape == img.shape and out.dtype == img.dtype
    one_row = _random_uint8((3, 1, 7), 3)
    torch.testing.assert_close(EMColorStrip("strong")(one_row), one_row, atol=0, rtol=0)


def test_intensity_zero_is_identity_and_thinning_below_weak_is_monotone_for_any_image():
    img = torch.rand(3, 64, 32, generator=torch.Generator().manual_seed(4))
    attack = EMColorStrip()
    torch.testing.assert_close(attack.apply_params(img, attack.sample_params(1, 64, 32, intensity=0.0)), img)
    distortions = []
    for s in torch.linspace(0, LEVELS["weak"], 13):
        params = attack.sample_params(1, 64, 32, intensity=s)
        distortions.append(_mad(attack.apply_params(img, params), img))
    assert distortions[0] == 0.0
    assert all(b >= a for a, b in itertools.pairwise(distortions))
    assert distortions[-1] > 0


def test_between_levels_distortion_moves_linearly_from_level_to_level():
    img = torch.rand(3, 80, 16, generator=torch.Generator().manual_seed(5))
    attack = EMColorStrip()

    def mad_at(s):
        return _mad(attack.apply_params(img, attack.sample_params(1, 80, 16, intensity=s)), img)

    for low, high in ((1 / 3, 2 / 3), (2 / 3, 1.0)):
        for t in (0.25, 0.5, 0.75):
            expected = (1 - t) * mad_at(low) + t * mad_at(high)
            assert mad_at(low + t * (high - low)) == pytest.approx(expected, rel=1e-4, abs=1e-6)


def test_params_mapping_hits_levels():
    s = torch.tensor([0.0, 1 / 6, 1 / 3, 0.5, 2 / 3, 1.0])
    params = stripe_params_for(s)
    assert params["band_fraction"].tolist() == pytest.approx([0.0, 0.5, 1.0, 1.0, 1.0, 1.0], abs=1e-5)
    effective = torch.where(params["mix"] > 0.5, params["next_num_stripes"], params["num_stripes"])
    assert effective[2:].tolist() == [8.0, 8.0, 12.0, 16.0]
    assert params["mix"][3].item() == pytest.approx(0.5, abs=1e-5)  # halfway between weak and medium


def test_batch_with_per_sample_parameters_matches_single_calls():
    imgs = _random_uint8((6, 3, 40, 20), 6)
    attack = EMColorStrip((0.0, 1.0))  # continuous: thinned bands and cross-fades, one pattern per sample
    params = attack.sample_params(6, 40, 20, generator=torch.Generator().manual_seed(1))
    assert len(set(params["intensity"].tolist())) == 6
    out = attack.apply_params(imgs, params)
    for i in range(6):
        single = {k: v[i : i + 1] for k, v in params.items()}
        torch.testing.assert_close(
            out[i : i + 1], attack.apply_params(imgs[i : i + 1], single), atol=0, rtol=0
        )


def test_broadcast_params_and_channels():
    imgs = _random_uint8((3, 4, 20, 20), 7)
    attack = EMColorStrip("medium")
    params = attack.sample_params(1, 20, 20)
    out = attack.apply_params(imgs, params)
    torch.testing.assert_close(out[:, 3], imgs[:, 3], atol=0, rtol=0)  # alpha untouched
    torch.testing.assert_close(out[:, :3], em_color_strip(imgs[:, :3], 12), atol=0, rtol=0)
    floats = torch.rand(2, 3, 20, 20, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    out64 = attack(floats)
    assert out64.dtype == torch.float64 and out64.min() >= 0 and out64.max() <= 1


def test_fixed_num_stripes_and_pickle_and_seed():
    img = _random_uint8((2, 3, 30, 30), 8)
    torch.testing.assert_close(
        EMColorStrip("weak", num_stripes=4)(img), em_color_strip(img, 4), atol=0, rtol=0
    )
    a = EMColorStrip("random", seed=9)
    b = pickle.loads(pickle.dumps(EMColorStrip("random", seed=9)))
    torch.testing.assert_close(a(img), b(img), atol=0, rtol=0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"num_stripes": 0}, "num_stripes"),
        ({"num_stripes": float("nan")}, "num_stripes"),
        ({"num_stripes": 8, "band_fraction": 1.5}, "band_fraction"),
        ({"num_stripes": 8, "next_num_stripes": 12, "mix": -0.1}, "mix"),
        ({"num_stripes": torch.tensor([8.0, 12.0, 16.0])}, "one value per sample"),
    ],
)
def test_bad_parameters_raise_clear_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        em_color_strip(_random_uint8((2, 3, 10, 10), 0), **kwargs)
    with pytest.raises(ValueError, match="num_stripes"):
        EMColorStrip(num_stripes=0)


def test_full_hd_frame_keeps_shape_and_dtype():
    frame = _random_uint8((3, 1080, 1920), seed=12)
    out = EMColorStrip("strong")(frame)
    assert out.shape == frame.shape and out.dtype == frame.dtype and not torch.equal(out, frame)


@pytest.mark.parametrize("intensity", ["weak", "strong", (0.0, 1.0), "random", 0.9])
@pytest.mark.parametrize("channels", [3, 4, 1])
def test_uint8_kernel_is_within_one_grey_level_of_the_float_path(intensity, channels):
    """uint8 images never take the float round trip; the result is the float path's within one grey level."""
    imgs = _random_uint8((5, channels, 37, 29), seed=channels)
    attack = EMColorStrip(intensity)
    params = attack.sample_params(5, 37, 29, generator=torch.Generator().manual_seed(2))
    out = attack.apply_params(imgs, params)
    out_float = attack.apply_params(imgs.float() / 255, params)
    assert out.dtype == torch.uint8 and out.shape == imgs.shape
    assert float((out_float.double() * 255 - out.double()).abs().max()) <= 1.0
    assert not torch.equal(out, imgs)


def test_random_draws_the_authors_integer_stripe_counts():
    """ "random" = the authors' training: N = randint(8, 16), each the paper's pattern for that N exactly."""
    attack = EMColorStrip("random")
    params = attack.sample_params(900, 64, 64, generator=torch.Generator().manual_seed(3))
    stripes = params["num_stripes"]
    assert set(stripes.tolist()) == set(range(8, 17))
    assert (params["mix"] == 0).all() and (params["band_fraction"] == 1).all()
    counts = torch.bincount(stripes.long(), minlength=17)[8:].double()
    assert float((counts / 900 - 1 / 9).abs().max()) < 0.04  # uniform over the nine counts
    imgs = _random_uint8((4, 3, 50, 20), seed=4)
    small = attack.sample_params(4, 50, 20, generator=torch.Generator().manual_seed(5))
    out = attack.apply_params(imgs, small)
    for i in range(4):
        expected = _reference(imgs[i], int(small["num_stripes"][i]))
        torch.testing.assert_close(out[i], expected, atol=0, rtol=0)


@pytest.mark.parametrize("dtype", [torch.uint8, torch.float32])
def test_random_batch_equals_each_sample_on_its_own(dtype):
    """ "random" groups the batch by stripe count (one copy in group order, one back): each sample's output is the
    one it gets alone."""
    images = _random_uint8((10, 3, 50, 30), 8)
    images = images if dtype == torch.uint8 else images.float() / 255
    attack = EMColorStrip("random", seed=1)
    params = attack.sample_params(10, 50, 30, generator=torch.Generator().manual_seed(2))
    assert len(set(params["num_stripes"].tolist())) > 2
    out = attack.apply_params(images, params)
    for i in range(10):
        alone = {k: v[i : i + 1] for k, v in params.items()}
        assert torch.equal(out[i : i + 1], attack.apply_params(images[i : i + 1], alone)), f"sample {i}"


@pytest.mark.parametrize("intensity", ["strong", "random"])
def test_float_batch_corrupted_chunk_by_chunk_equals_one_chunk(intensity, monkeypatch):
    """Float batches are clamped and corrupted a few images at a time (``FLOAT_CHUNK_BYTES``, in cache): chunks of
    two images give the output of one chunk, clamped to [0, 1] first."""
    images = _random_uint8((7, 3, 50, 30), 9).float() / 255 * 1.2 - 0.1  # values outside [0, 1] too
    attack = EMColorStrip(intensity, seed=1)
    params = attack.sample_params(7, 50, 30, generator=torch.Generator().manual_seed(3))
    whole = attack.apply_params(images, params)
    monkeypatch.setattr(em_color_strip_module, "FLOAT_CHUNK_BYTES", 2 * images[0].numel() * 4)
    chunked = attack.apply_params(images, params)
    assert torch.equal(chunked, whole)
    assert float(whole.min()) == 0.0 and float(whole.max()) == 1.0
    assert not torch.equal(whole, images.clamp(0, 1))


@pytest.mark.parametrize("num_stripes", [9, 11, 13])
def test_a_last_band_whose_period_runs_past_the_frame_is_corrupted_exactly(num_stripes):
    """At 224 rows, 9, 11 and 13 stripes leave a last band whose period (band + gap) runs past the frame's end;
    the bands are still corrupted through one strided view: the batch equals the paper's code per image."""
    images = _random_uint8((2, 3, 224, 24), seed=num_stripes)
    step = 224 // num_stripes
    last_band = max(range(0, 224 - step, 2 * step))
    assert last_band + 2 * step > 224  # the case this test is about
    out = em_color_strip(images, num_stripes)
    for i in range(2):
        torch.testing.assert_close(out[i], _reference(images[i], num_stripes), atol=0, rtol=0)


@pytest.mark.parametrize("model", ["paper", "bayer_phase_flip"])
def test_a_demosaic_pattern_mis_decodes_the_same_rows_through_the_demosaic_after_a_lost_line(model):
    """The rows the model mis-decodes are the ones ``physics.em_demosaic_rows`` moves (the calibrated
    ``bayer_demosaic``), per sample in a batch, for uint8 and float, picklable."""
    from lerobot_phantom.transforms import physics

    frames = torch.rand(3, 3, 24, 20, generator=torch.Generator().manual_seed(5))
    options = {"model": model, "gain": 1.3, "offset": 0.02}
    plain = EMColorStrip((0.1, 1.0), **options)
    demosaicing = pickle.loads(pickle.dumps(EMColorStrip((0.1, 1.0), **options, demosaic_pattern="GRBG")))
    params = demosaicing.sample_params(3, 24, 20, generator=torch.Generator().manual_seed(1))
    assert len(set(params["intensity"].tolist())) == 3
    if model == "paper":
        rows = (
            em_color_strip_module.row_weights_of(frames, params)[:, None, :, None].float().expand_as(frames)
        )
    else:
        rows = (plain.apply_params(frames, params) != frames).any(1, keepdim=True).expand_as(frames).float()
    terms, weights = physics.bayer_line_terms(frames, "GRBG")
    expected = physics.em_demosaic_rows(terms, weights, frames, rows[:, 0, :, 0], 1.3, 0.02)
    out = demosaicing.apply_params(frames, params)
    torch.testing.assert_close(out, expected)
    rows_per_sample = rows[:, 0, :, 0].sum(1)
    assert rows_per_sample.min() > 0 and rows_per_sample.max() < 24
    if model == "bayer_phase_flip":
        assert not torch.allclose(out, plain.apply_params(frames, params))
    as_uint8 = demosaicing.apply_params((frames * 255).round().to(torch.uint8), params)
    assert as_uint8.dtype == torch.uint8 and _mad(as_uint8, expected * 255) < 1.0
    with pytest.raises(ValueError, match="valid: None, RGGB, GRBG, GBRG, BGGR"):
        EMColorStrip(demosaic_pattern="rggb")


@pytest.mark.parametrize("intensity", [(0.1, 1.0), "strong"])
def test_a_measured_colour_map_colours_the_papers_bands(intensity):
    """``gain`` / ``offset`` (a camera's colour map, as lerobot-phantom-calibrate fits it) colour the rows the paper's
    bands mis-decode: the paper's blend of each row by its band weight, towards ``physics.em_color_map`` with the
    given map (until session 88 the paper's bands ignored them). With the paper's map that blend is the paper's
    own fast kernel; uint8 frames take the float path, rounded once."""
    from lerobot_phantom.transforms import physics

    image = torch.rand(3, 3, 24, 32, generator=torch.Generator().manual_seed(5))
    measured = EMColorStrip(intensity, gain=1.2, offset=0.05)
    params = measured.sample_params(3, 24, 32, generator=torch.Generator().manual_seed(0))
    weights = em_color_strip_module.row_weights_of(image, params)[:, None, :, None].float()
    for gain, offset in ((1.2, 0.05), (2.5, 50 / 255)):
        attack = EMColorStrip(intensity, gain=gain, offset=offset)
        blended = torch.lerp(image, physics.em_color_map(image, gain, offset), weights).clamp(0, 1)
        torch.testing.assert_close(attack.apply_params(image, params), blended, atol=1e-6, rtol=0)
    assert (
        float((measured.apply_params(image, params) - EMColorStrip().apply_params(image, params)).abs().max())
        > 0.1
    )
    as_uint8 = (image * 255).round().to(torch.uint8)
    expected = (measured.apply_params(as_uint8 / 255.0, params) * 255).round().to(torch.uint8)
    assert torch.equal(measured.apply_params(as_uint8, params), expected)
    assert "gain=1.2, offset=0.05" in repr(measured) and "gain" not in repr(EMColorStrip())
