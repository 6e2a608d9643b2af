import os
import pickle

import numpy as np
import pytest
import torch
from reference_optical import laser_blinding_reference

from lerobot_phantom.transforms import laser_blinding as laser_blinding_module
from lerobot_phantom.transforms.laser_blinding import (
    ALPHA_LEVELS,
    LaserBlinding,
    LaserPhysics,
    LaserSpot,
    laser_blinding,
)
from lerobot_phantom.transforms.patterns import (
    LASER_COLORS,
    exact_float64,
    laser_glare,
    laser_spot,
    load_pattern_image,
    parse_color,
    resize_pattern,
)

os.environ.setdefault("HF_HUB_OFFLINE", "1")

CPU = torch.device("cpu")


def _random_uint8(shape, seed):
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


def _hwc(chw: torch.Tensor) -> np.ndarray:
    return chw.permute(1, 2, 0).numpy()


@pytest.mark.parametrize("size", [(24, 32), (31, 17)])
@pytest.mark.parametrize("level", ["weak", "medium", "strong"])
def test_matches_paper_reference(size, level):
    img = _random_uint8((3, *size), seed=size[0] + len(level))
    attack = LaserBlinding(level, color="red")
    params = attack.sample_params(1, *size)
    pattern = attack.patterns_for(params["position"], *size, CPU)[0]
    alpha = float(params["alpha"][0])
    assert alpha == pytest.approx(
        dict(zip(("weak", "medium", "strong"), ALPHA_LEVELS[1:], strict=True))[level]
    )
    expected = laser_blinding_reference(_hwc(img), _hwc(pattern * 255.0), alpha)
    fast = attack.apply_params(img, params)
    assert np.abs(_hwc(fast).astype(int) - expected.astype(int)).max() <= 1
    functional = laser_blinding(img, alpha, pattern)
    assert np.abs(_hwc(functional).astype(int) - expected.astype(int)).max() <= 1


def test_functional_resizes_pattern_and_accepts_per_sample_alpha():
    img = _random_uint8((2, 3, 20, 30), seed=1)
    small = torch.full((3, 5, 7), 255, dtype=torch.uint8)  # a white pattern of another size
    out = laser_blinding(img, torch.tensor([0.0, 1.0]), small)
    assert torch.equal(out[0], img[0])
    assert bool((out[1] == 255).all())
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        laser_blinding(img, 1.5, small)


def test_pattern_has_white_core_coloured_ring_and_power_law_halo():
    height, width = 200, 200
    spot = laser_spot(
        height,
        width,
        center=(100.0, 100.0),
        core_radius=0.05,
        halo_exponent=2.0,
        color=(0, 1, 0),
        crosstalk=0.25,
    )
    core = spot[:, 100, 100]
    assert torch.allclose(core, torch.ones(3))  # every channel saturates: white
    ring = spot[:, 100, 100 + 20]  # r = 0.1 > core radius 0.05
    assert ring[1] == 1.0 and ring[0] < 1.0 and ring[2] < 1.0  # only the laser's channel clips
    halo_near, halo_far = spot[1, 100, 100 + 50], spot[1, 100, 100 + 99]
    assert 0 < halo_far < halo_near < 1
    # power law: the unsaturated halo falls off like r^-2 (ratio of intensities ~ (r1/r2)^2, core term negligible)
    assert float(halo_near / halo_far) == pytest.approx((99 / 50) ** 2, rel=0.05)


def test_pattern_scales_with_image_size():
    attack = LaserBlinding("strong")
    small = attack.patterns_for(torch.tensor([[0.5, 0.5]]), 96, 96, CPU)[0]
    large = attack.patterns_for(torch.tensor([[0.5, 0.5]]), 480, 480, CPU)[0]
    shrunk = torch.nn.functional.interpolate(large[None], size=(96, 96), mode="area")[0]
    assert (shrunk - small).abs().mean() < 0.02


@pytest.mark.parametrize("color", sorted(LASER_COLORS))
def test_laser_colour_dominates_the_halo(color):
    rgb = torch.tensor(parse_color(color))
    spot = LaserBlinding(color=color, streaks=0).render_pattern(64, 64, 32, 32, CPU)
    halo = spot[:, 32, 60]
    assert int(halo.argmax()) == int(rgb.argmax())


def test_rgb_triple_colour_and_bad_colour():
    assert parse_color((255, 128, 0)) == pytest.approx((1.0, 128 / 255, 0.0))
    with pytest.raises(ValueError, match="red"):
        LaserBlinding(color="purple-ish")


def test_random_position_is_per_sample_and_seeded():
    attack = LaserBlinding("strong", position="random", seed=3)
    img = torch.zeros(6, 3, 40, 50, dtype=torch.uint8)
    out = attack(img)
    brightest = [int(o.float().sum(0).argmax()) for o in out]
    assert len(set(brightest)) > 1
    again = LaserBlinding("strong", position="random", seed=3)(img)
    assert torch.equal(out, again)


def test_fixed_position_places_spot_where_asked():
    attack = LaserBlinding("strong", position=(0.25, 0.75), streaks=0)
    out = attack(torch.zeros(3, 41, 81))
    brightest = torch.nonzero(out.sum(0) >= out.sum(0).max() - 1e-6).float()
    row, col = brightest.mean(0).tolist()  # centre of the saturated core
    assert (row, col) == pytest.approx((30.0, 20.0), abs=1e-6)


def test_canvas_crop_equals_direct_render():
    attack = LaserBlinding("strong", position="random", seed=0)
    params = attack.sample_params(4, 23, 37, generator=torch.Generator().manual_seed(5))
    batch = attack.patterns_for(params["position"], 23, 37, CPU)
    pixels = attack.spot_pixel(params["position"], 23, 37)
    for i in range(4):
        direct = attack.render_pattern(23, 37, int(pixels[i, 0]), int(pixels[i, 1]), CPU)
        assert torch.allclose(batch[i], direct, atol=1e-6)


def _write_png(path, array):
    from PIL import Image

    Image.fromarray(array).save(path)


def test_user_pattern_is_loaded_once_and_used(tmp_path):
    array = np.zeros((10, 10, 3), dtype=np.uint8)
    array[:, :5] = (255, 0, 0)
    path = tmp_path / "capture.png"
    _write_png(path, array)
    attack = LaserBlinding("strong", pattern=path)
    path.unlink()  # a per-call reload (the paper code's defect) would now fail
    out = attack(torch.zeros(3, 20, 20, dtype=torch.uint8))
    assert out[0, :, :8].float().mean() > 200 and out[0, :, 12:].float().mean() < 5
    clone = pickle.loads(pickle.dumps(attack))
    assert torch.equal(clone(torch.zeros(3, 20, 20, dtype=torch.uint8)), out)


def test_user_pattern_shifted_with_random_position(tmp_path):
    array = np.zeros((9, 9, 3), dtype=np.uint8)
    array[4, 4] = 255
    path = tmp_path / "dot.png"
    _write_png(path, array)
    attack = LaserBlinding("strong", pattern=path, position="random", seed=1)
    out = attack(torch.zeros(5, 3, 9, 9))
    peaks = {int(o.sum(0).argmax()) for o in out}
    assert len(peaks) > 1


def test_missing_pattern_and_bad_parameters_raise():
    with pytest.raises(FileNotFoundError, match=r"nothing\.png"):
        LaserBlinding(pattern="nothing.png")
    with pytest.raises(ValueError, match="random"):
        LaserBlinding(position="somewhere")
    with pytest.raises(ValueError, match="levels"):
        LaserBlinding(levels=(0.1, 0.2, 0.3, 0.4))
    with pytest.raises(ValueError, match="core_radius"):
        LaserBlinding(core_radius=0.0)


def test_levels_override_changes_alpha():
    attack = LaserBlinding("strong", levels=(0.0, 0.2, 0.4, 0.6))
    assert float(attack.sample_params(1, 8, 8)["alpha"][0]) == pytest.approx(0.6)


def test_default_pattern_is_a_red_glare_flooding_the_frame():
    attack = LaserBlinding("strong")
    assert attack.pattern == "red"
    pattern = attack.patterns_for(torch.tensor([[0.5, 0.5]]), 224, 224, CPU)[0]
    assert torch.equal(pattern, laser_glare(224, 224))
    assert torch.equal(pattern[:, 112, 112], torch.ones(3))  # white core
    corner = pattern[:, 0, 0]
    assert corner[0] > 0.75 and corner[1] < 0.1 and corner[2] < 0.3  # the red field reaches the corners
    assert torch.equal(torch.round(pattern * 255) / 255, pattern)  # an 8-bit pattern, like a capture
    # the authors' red.png (README of their patterns): mean colour (245, 79, 132); here within 4 grey levels
    mean = (pattern.mean((1, 2)) * 255).tolist()
    assert mean == pytest.approx([245, 79, 132], abs=4)


def test_glare_stretches_with_the_frame_like_a_resized_capture():
    square = laser_glare(200, 200)
    wide = laser_glare(100, 300)
    shrunk = resize_pattern(square, 100, 300)
    assert (wide - shrunk).abs().mean() < 0.01


@pytest.mark.parametrize("level", ["weak", "medium", "strong"])
@pytest.mark.parametrize("position", ["center", "random"])
@pytest.mark.parametrize("pattern", ["red", "spot"])
def test_uint8_path_matches_float_path(level, position, pattern):
    img = _random_uint8((5, 3, 30, 44), seed=3)
    attack = LaserBlinding(level, pattern=pattern, position=position, seed=1)
    params = attack.sample_params(5, 30, 44, generator=torch.Generator().manual_seed(7))
    fast = attack.apply_params(img, params)
    assert torch.equal(fast, attack._apply_uint8(img, params))  # apply_params took the uint8 kernel
    slow = torch.round(attack.apply_params(img.float() / 255, params) * 255).to(torch.uint8)
    assert (fast.int() - slow.int()).abs().max() <= 1
    single = attack.apply_params(img[1], {k: v[1:2] for k, v in params.items()})
    assert torch.equal(single, fast[1])


def test_uint8_kernel_in_chunks_with_level_and_other_alphas_mixed(monkeypatch):
    """The uint8 kernel blends a few images per op (``UINT8_CHUNK_BYTES``): chunks mixing the level table's alphas
    (cached offset) with other alphas (lerp) give each image the blend it gets alone, the float path's blend
    rounded."""
    img = _random_uint8((7, 3, 18, 26), seed=4)
    monkeypatch.setattr(laser_blinding_module, "UINT8_CHUNK_BYTES", 3 * img[0].numel() * 4)
    attack = LaserBlinding("strong", seed=0)
    intensity = torch.tensor(
        [1 / 3, 1 / 3, 0.5, 1.0, 1.0, 1.0, 0.8]
    )  # weak, weak, between, strong x3, between
    params = attack.sample_params(7, 18, 26, intensity=intensity)
    fast = attack.apply_params(img, params)
    exact = attack.apply_params(img.float() / 255, params).double() * 255
    # equal to the float path's rounded value but at ties (x.5: the saturated glare core at alpha 0.9 gives
    # 229.5 + 0.1 x), which the kernel rounds up and torch.round to even
    tie = ((exact - exact.floor()) - 0.5).abs() < 1e-3
    assert torch.equal(fast[~tie], torch.round(exact[~tie]).to(torch.uint8))
    assert ((fast.double() - exact)[tie].abs() <= 0.5 + 1e-3).all()
    for i in range(7):
        alone = attack.apply_params(img[i], {k: v[i : i + 1] for k, v in params.items()})
        assert torch.equal(alone, fast[i]), f"image {i}"


def test_uint8_kernel_leaves_the_physical_model_to_the_float_path():
    attack = LaserBlinding("strong", model="physical", gain=2.0)
    img = _random_uint8((2, 3, 16, 16), seed=0)
    params = attack.sample_params(2, 16, 16)
    assert attack._apply_uint8(img, params) is NotImplemented
    assert attack.apply_params(img, params).dtype == torch.uint8


def test_options_objects_and_flat_options_are_the_same():
    flat = LaserBlinding(color="red", core_radius=0.05, gain=1.5, model="physical")
    grouped = LaserBlinding(
        spot=LaserSpot(color="red", core_radius=0.05), physics={"gain": 1.5}, model="physical"
    )
    assert flat.spot == grouped.spot and flat.physics == grouped.physics == LaserPhysics(gain=1.5)
    assert flat.pattern == grouped.pattern == "spot"  # spot options (and the physical model) use the spot
    with pytest.raises(TypeError, match="core_radius"):
        LaserBlinding(core_radis=0.1)
    with pytest.raises(ValueError, match="spot"):
        LaserBlinding(pattern="red", color="green")
    with pytest.raises(ValueError, match="glare_scale_ref_px"):
        LaserPhysics(glare_scale_ref_px=0.0)
    with pytest.raises(ValueError, match="red"):
        LaserBlinding(pattern="laser")


def test_random_intensity_draws_alpha_uniform_in_authors_range():
    attack = LaserBlinding("random")
    params = attack.sample_params(2000, 8, 8, generator=torch.Generator().manual_seed(0))
    alpha, s = params["alpha"], params["intensity"]
    assert float(alpha.min()) >= 0.1 - 1e-6 and float(alpha.max()) <= 0.9 + 1e-6
    assert float((alpha < 0.5).float().mean()) == pytest.approx(0.5, abs=0.04)
    assert float(s.min()) >= 1 / 3 - 1e-6 and float(s.max()) <= 1.0


def test_resize_pattern_is_pil_lanczos():
    from PIL import Image

    array = _random_uint8((9, 13, 3), seed=5).numpy()
    expected = np.asarray(Image.fromarray(array).resize((31, 20), Image.Resampling.LANCZOS))
    as_uint8 = resize_pattern(torch.from_numpy(array).permute(2, 0, 1), 20, 31)
    as_float = resize_pattern(torch.from_numpy(array).permute(2, 0, 1).float() / 255, 20, 31)
    assert np.array_equal(_hwc(as_uint8), expected)
    assert np.array_equal(_hwc(torch.round(as_float * 255).to(torch.uint8)), expected)
    smooth = torch.rand(3, 9, 13, generator=torch.Generator().manual_seed(1))  # off the 8-bit grid
    assert resize_pattern(smooth, 20, 31).shape == (3, 20, 31)


def test_a_loaded_capture_widens_to_the_calibrations_float64_values_bit_for_bit(tmp_path):
    # the attack reads a capture as the fit reads it (read_capture's thresholds see the last bits: session 97)
    from PIL import Image

    from lerobot_phantom.calibration.frame_models.common import load_rgb

    Image.fromarray(_random_uint8((9, 13, 3), seed=7).numpy()).save(tmp_path / "capture.png")
    loaded = load_pattern_image(tmp_path / "capture.png", keep_alpha=False)
    calibration_reads = load_rgb(tmp_path / "capture.png")
    assert not torch.equal(loaded.double(), calibration_reads)
    assert torch.equal(exact_float64(loaded), calibration_reads)
    off_grid = torch.tensor([0.3, 0.5 / 255], dtype=torch.float32)
    assert torch.equal(exact_float64(off_grid), off_grid.double())


def test_exposure_spread_scales_each_samples_laser_power_by_a_lognormal_factor():
    attack = LaserBlinding("medium", model="physical", gain=0.5, exposure_spread=0.4)
    logs = torch.log(
        attack.sample_params(4000, 16, 16, generator=torch.Generator().manual_seed(0))["exposure"]
    )
    assert float(logs.std()) == pytest.approx(0.4, rel=0.05) and abs(float(logs.mean())) < 0.03
    # without a spread nothing is drawn: every other draw stays as it was
    plain = LaserBlinding("medium", model="physical", gain=0.5)
    assert "exposure" not in plain.sample_params(2, 16, 16, generator=torch.Generator().manual_seed(0))
    # the factor multiplies the laser's power: each sample is the plain model at that sample's gain
    img = torch.rand(2, 3, 16, 16, generator=torch.Generator().manual_seed(2))
    params = attack.sample_params(2, 16, 16, generator=torch.Generator().manual_seed(1))
    out = attack.apply_params(img, params)
    assert not torch.allclose(params["exposure"][0], params["exposure"][1])
    for b in range(2):
        one = {k: v[b : b + 1] for k, v in params.items() if k != "exposure"}
        at_gain = LaserBlinding("medium", model="physical", gain=0.5 * float(params["exposure"][b]))
        assert torch.allclose(out[b : b + 1], at_gain.apply_params(img[b : b + 1], one), atol=1e-6)
    with pytest.raises(ValueError, match="Generator"):
        attack.sample_params(2, 16, 16)
    with pytest.raises(ValueError, match="exposure_spread"):
        LaserPhysics(exposure_spread=-0.1)


def test_colour_correction_is_validated_and_reaches_the_physical_model():
    matrix = (1.4, -0.2, -0.2, -0.3, 1.5, -0.2, -0.1, -0.3, 1.4)
    img = torch.rand(2, 3, 16, 16, generator=torch.Generator().manual_seed(4))
    params = LaserBlinding("strong", model="physical", gain=3.0).sample_params(
        2, 16, 16, generator=torch.Generator().manual_seed(5)
    )
    plain = LaserBlinding("strong", model="physical", gain=3.0).apply_params(img, params)
    corrected = LaserBlinding("strong", model="physical", gain=3.0, colour_correction=list(matrix))
    assert corrected.physics.colour_correction == matrix
    assert not torch.allclose(corrected.apply_params(img, params), plain, atol=1e-3)
    identity = LaserBlinding(
        "strong", model="physical", gain=3.0, colour_correction=(1, 0, 0, 0, 1, 0, 0, 0, 1)
    )
    assert torch.allclose(identity.apply_params(img, params), plain, atol=1e-5)
    for bad in ((1.0, 0.0), (1.5, 0, 0, 0, 1, 0, 0, 0, 1)):
        with pytest.raises(ValueError, match="rows sum to 1"):
            LaserPhysics(colour_correction=bad)


def _capture_file(tmp_path, height=48, width=64, spot=(44, 14), dark=12):
    """A capture of the laser alone: a dark room at ``dark`` grey levels and a saturated green spot of radius 3
    centred at pixel (x, y) = ``spot``, saved as a PNG."""
    from PIL import Image

    ys, xs = np.mgrid[0:height, 0:width]
    image = np.full((height, width, 3), dark, dtype=np.uint8)
    image[np.hypot(xs - spot[0], ys - spot[1]) <= 3] = (40, 255, 40)
    path = tmp_path / "capture.png"
    Image.fromarray(image).save(path)
    return path


def test_a_physical_attack_fed_a_capture_takes_out_its_dark_level_and_centres_the_glare_on_its_spot(tmp_path):
    """``model="physical"`` with a capture as its pattern reads it as lerobot-phantom-calibrate does: the dark room's
    level is no laser light (scaled by the gain it brightened the whole frame), and the glare is centred on the
    capture's spot (``physics.pattern_centre``), which ``position`` moves with the capture."""
    from lerobot_phantom.transforms import physics

    capture = _capture_file(tmp_path)
    scene = torch.full((1, 3, 48, 64), 0.2)
    options = {"model": "physical", "gain": 20.0, "gamma": 1.0}
    far = (slice(None), slice(None), slice(40, 48), slice(0, 8))  # the frame's corner farthest from the spot
    fed = LaserBlinding(0.5, pattern=str(capture), **options)(scene)
    torch.testing.assert_close(fed[far], scene[far])
    # the same capture with the room's level added as laser light: 0.2 + 10 * 12 / 255 on every pixel
    as_light = physics.laser_injection(scene, fed.new_tensor(12 / 255).expand(1, 3, 48, 64), 10.0, gamma=1.0)
    assert float(as_light[far].min()) > 0.6
    glare = {
        "glare_amplitude": 0.5,
        "glare_exponent": 1.5,
        "glare_scale_ref_px": 4.0,
        "color": (0.0, 1.0, 0.0),
    }
    dark_scene = torch.zeros(1, 3, 48, 64)
    lit = LaserBlinding(0.5, pattern=str(capture), **options, **glare)(dark_scene)[0, 1]
    # symmetric about the capture's spot at (x, y) = (44, 14), not about the frame's centre
    torch.testing.assert_close(lit[14, 44 - 10], lit[14, 44 + 10])
    torch.testing.assert_close(lit[14 - 9, 44], lit[14 + 9, 44])
    assert float(lit[14, 34]) > 2 * float(lit[40, 10])
    # position puts the capture's centre (32, 24 here) at (0.25, 0.5): the spot and its glare move by (-16, 0)
    moved = LaserBlinding(0.5, pattern=str(capture), position=(0.25, 0.5), **options, **glare)(dark_scene)[
        0, 1
    ]
    torch.testing.assert_close(moved[14, 28 - 10], moved[14, 28 + 10])
    torch.testing.assert_close(moved[:, 10:40], lit[:, 26:56])


def test_under_a_colour_correction_a_capture_is_read_in_its_laser_channel_and_raw_colour(tmp_path):
    """With ``raw_colour`` the capture's laser channel (green here) is read alone and spread over the raw channels
    in that colour, over the share of it the matrix leaves in the laser's channel: on a black scene below the clip
    the frame stores the capture's laser channel again, and the others as the matrix mixes the raw colour (red at
    0.18 / 1.37 of green, blue pushed below 0). Options that do not fit are refused, naming what is valid."""
    matrix = (1.4, -0.2, -0.2, -0.3, 1.5, -0.2, -0.1, -0.3, 1.4)
    capture = _capture_file(tmp_path)
    options = {"model": "physical", "gain": 0.5, "gamma": 1.0, "colour_correction": matrix}
    black = torch.zeros(1, 3, 48, 64)
    spot = LaserBlinding(1.0, pattern=str(capture), raw_colour=(0.3, 1.0, 0.2), **options)(black)[
        0, :, 14, 44
    ]
    plain = {k: v for k, v in options.items() if k != "colour_correction"}
    read_without_matrix = LaserBlinding(1.0, pattern=str(capture), **plain)(black)[0, 1, 14, 44]
    assert float(spot[1]) == pytest.approx(float(read_without_matrix), rel=1e-5)
    assert float(spot[0] / spot[1]) == pytest.approx(0.18 / 1.37, rel=1e-5) and float(spot[2]) < 1e-6
    stored = LaserBlinding(1.0, pattern=str(capture), **options)(black)[0, :, 14, 44]
    assert float(stored[0] / stored[1]) != pytest.approx(0.18 / 1.37, rel=0.1)
    with pytest.raises(ValueError, match="holds its laser light in channel 1"):
        LaserBlinding(1.0, pattern=str(capture), raw_colour=(1.0, 0.4, 0.2), **options)
    for bad in (
        {"raw_colour": (1.0, 0.2, 0.1)},
        {"raw_colour": (0.5, 0.2, 0.1), "colour_correction": matrix},
    ):
        with pytest.raises(ValueError, match="largest is 1"):
            LaserPhysics(**bad)


def test_a_captures_noise_is_not_scaled_into_the_frame_as_laser_light(tmp_path):
    """The capture's pixel noise about its dark level is read as noise, not light (``capture.beam_profile``): at a
    gain of 40 the frame far from the spot stays as even as the scene, where the capture as stored (its dark level
    out) would have scaled every noisy pixel above the level into tens of grey levels of speckle."""
    from PIL import Image

    from lerobot_phantom.transforms import physics

    rng = np.random.default_rng(3)
    path = _capture_file(tmp_path)
    image = np.asarray(Image.open(path)).astype(np.int16)
    noisy = np.clip(image + rng.normal(0.0, 2.0, image.shape).round(), 0, 255).astype(np.uint8)
    Image.fromarray(noisy).save(path)
    scene = torch.full((1, 3, 48, 64), 0.2)
    options = {"model": "physical", "gain": 40.0, "gamma": 1.0}
    far = (0, slice(None), slice(36, 48), slice(0, 16))
    fed = LaserBlinding(1.0, pattern=str(path), **options)(scene)
    assert float(fed[far].std()) < 2 / 255
    stored = torch.from_numpy(noisy).permute(2, 0, 1).float()[None] / 255
    as_stored = physics.laser_injection(scene, (stored - 12 / 255).clamp(min=0.0), 40.0, gamma=1.0)
    assert float(as_stored[far].std()) > 10 / 255


def test_a_captures_saturated_core_is_continued_at_the_calibrated_width(tmp_path):
    """A capture saturated in its core recorded at least the full well there: at a laser a fifth of the capture's
    power the core held at the full well turns grey, continued as a Gaussian beam (``core_sigma_ref_px``) its
    centre stays white, the more so the narrower the beam."""
    capture = _capture_file(tmp_path)
    scene = torch.zeros(1, 3, 48, 64)
    options = {"model": "physical", "gain": 0.2, "gamma": 1.0}
    held = LaserBlinding(1.0, pattern=str(capture), **options)(scene)[0, 1, 14, 44]
    wide = LaserBlinding(1.0, pattern=str(capture), core_sigma_ref_px=30.0, **options)(scene)[0, 1, 14, 44]
    narrow = LaserBlinding(1.0, pattern=str(capture), core_sigma_ref_px=3.0, **options)(scene)[0, 1, 14, 44]
    assert 0.15 < float(held) < 0.2  # the full well less the dark level, times the power ratio
    assert float(held) < float(wide) < float(narrow) and float(narrow) == 1.0
    # a narrower beam at the core's centre (inner_core_peak over the saturated level) brightens it further
    inner = LaserBlinding(
        1.0,
        pattern=str(capture),
        core_sigma_ref_px=30.0,
        inner_core_peak=3.0,
        inner_core_sigma_ref_px=20.0,
        **options,
    )(scene)[0, 1, 14, 44]
    assert float(wide) < float(inner)
    with pytest.raises(ValueError, match="core_sigma_ref_px > 0"):
        LaserPhysics(core_sigma_ref_px=0.0)
    with pytest.raises(ValueError, match="inner_core_peak must be >= 0"):
        LaserPhysics(core_sigma_ref_px=30.0, inner_core_peak=-1.0)
    with pytest.raises(ValueError, match="give core_sigma_ref_px too, or inner_core_peak 0"):
        LaserPhysics(inner_core_peak=2.0)


def test_the_meter_darkens_the_frame_by_its_power_and_excludes_the_divisor():
    scene = torch.full((1, 3, 32, 32), 0.4)
    params = LaserBlinding("strong", model="physical", gain=5.0).sample_params(1, 32, 32)
    plain = LaserBlinding("strong", model="physical", gain=5.0).apply_params(scene, params)
    half = LaserBlinding("strong", model="physical", gain=5.0, meter_power=0.5).apply_params(scene, params)
    full = LaserBlinding("strong", model="physical", gain=5.0, meter_power=1.0).apply_params(scene, params)
    corner = (0, slice(None), 0, 0)
    assert float(full[corner].mean()) < float(half[corner].mean()) < float(plain[corner].mean())
    with pytest.raises(ValueError, match="two auto-exposures"):
        LaserPhysics(auto_exposure=1.0, meter_power=1.0)


def test_a_luminance_meter_reaches_the_physical_model_and_is_validated():
    """``meter_reads="luminance"``: a blue laser weighs a fifth of the channel mean's weight in the meter's reading,
    so the frame it blinds stays brighter; any other reading is refused, naming the valid ones."""
    scene = torch.full((1, 3, 32, 32), 0.4)
    options = {"model": "physical", "gain": 20.0, "color": (0, 0, 255), "meter_power": 1.0}
    params = LaserBlinding("strong", **options).sample_params(1, 32, 32)
    channel_mean = LaserBlinding("strong", **options).apply_params(scene, params)
    luminance = LaserBlinding("strong", **options, meter_reads="luminance").apply_params(scene, params)
    corner = (0, slice(None), 0, 0)
    assert float(channel_mean[corner].mean()) < float(luminance[corner].mean()) < 0.4
    with pytest.raises(ValueError, match="meter_reads 'luma'; valid: channel_mean, luminance"):
        LaserPhysics(meter_reads="luma")
