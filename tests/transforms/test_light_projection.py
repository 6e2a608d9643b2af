import os
import pickle

import numpy as np
import pytest
import torch
from reference_optical import light_projection_reference

from lerobot_phantom.transforms.light_projection import (
    TRANSPARENCY_LEVELS,
    LightProjection,
    light_projection,
    placement,
)
from lerobot_phantom.transforms.patterns import PROJECTION_SHAPES, projection_shape

os.environ.setdefault("HF_HUB_OFFLINE", "1")

CPU = torch.device("cpu")


def _random_uint8(shape, seed):
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


def _hwc(chw: torch.Tensor) -> np.ndarray:
    return chw.permute(1, 2, 0).numpy()


def _watermark_uint8(attack, height, width):
    return torch.round(attack.watermark(height, width, CPU) * 255.0).to(torch.uint8)


@pytest.mark.parametrize("size", [(24, 32), (31, 17)])
@pytest.mark.parametrize("level", ["weak", "medium", "strong"])
@pytest.mark.parametrize(
    ("pattern", "offset"), [("stop_sign", (0, 0)), ("can", (40, -25)), ("arrow", (-60, 10))]
)
def test_matches_paper_reference(size, level, pattern, offset):
    height, width = size
    img = _random_uint8((3, height, width), seed=height * 3 + len(level))
    attack = LightProjection(level, pattern=pattern, size=0.8, x_offset=offset[0], y_offset=offset[1])
    params = attack.sample_params(1, height, width)
    t = float(params["transparency"][0])
    assert t == pytest.approx(
        dict(zip(("weak", "medium", "strong"), TRANSPARENCY_LEVELS[1:], strict=True))[level]
    )
    wm = _watermark_uint8(attack, height, width)
    dx, dy = round(offset[0] * width / 256), round(offset[1] * height / 256)
    expected = light_projection_reference(_hwc(img), _hwc(wm), t, dx, dy)
    fast = attack.apply_params(img, params)
    assert np.abs(_hwc(fast).astype(int) - expected.astype(int)).max() <= 1
    functional = light_projection(img, wm, t, dx, dy)
    assert np.abs(_hwc(functional).astype(int) - expected.astype(int)).max() <= 1
    if level == "strong":
        assert not np.array_equal(expected, _hwc(img))  # the watermark is actually on the image


def test_per_sample_offsets_match_one_by_one():
    img = _random_uint8((5, 3, 30, 40), seed=7)
    attack = LightProjection((0.34, 1.0), position="random", seed=2)
    params = attack.sample_params(5, 30, 40, generator=torch.Generator().manual_seed(9))
    batch = attack.apply_params(img, params)
    for i in range(5):
        single = attack.apply_params(img[i], {k: v[i : i + 1] for k, v in params.items()})
        assert torch.equal(batch[i], single)
    assert len({tuple(o) for o in params["offset"].tolist()}) == 5


def test_offsets_scale_with_image_size():
    offset = torch.tensor([[64.0, -32.0]])
    top_small, left_small = placement(96, 96, 10, 10, offset)
    top_large, left_large = placement(480, 640, 50, 50, offset)
    assert (int(left_small) + 5 - 48) / 96 == pytest.approx((int(left_large) + 25 - 320) / 640, abs=0.02)
    assert (int(top_small) + 5 - 48) / 96 == pytest.approx((int(top_large) + 25 - 240) / 480, abs=0.02)


def test_watermark_size_is_relative_and_cached():
    attack = LightProjection(pattern="stop_sign", size=0.5)
    assert attack.watermark(96, 128).shape == (4, 48, 48)
    assert attack.watermark(480, 640).shape == (4, 240, 240)
    assert attack.watermark(96, 128) is attack.watermark(96, 128)
    assert LightProjection(size=0.5).watermark(96, 128).shape == (4, 48, 40)  # the can: longer side 48


def test_native_size_keeps_the_pattern_pixels_on_every_frame(tmp_path):
    from PIL import Image

    default = LightProjection()
    for height, width in [(96, 96), (224, 224), (480, 640)]:
        assert default.watermark(height, width).shape == (4, 50, 42)  # the authors' can.png is 50x42
    array = np.zeros((7, 11, 4), dtype=np.uint8)
    array[..., 0], array[..., 3] = 200, 255
    path = tmp_path / "logo.png"
    Image.fromarray(array, mode="RGBA").save(path)
    native = LightProjection("strong", pattern=path, size="native")
    assert native.watermark(300, 400).shape == (4, 7, 11)
    assert torch.equal(native.watermark(300, 400), torch.from_numpy(array).permute(2, 0, 1).float() / 255)
    with pytest.raises(ValueError, match="native"):
        LightProjection(size="big")


def test_default_covers_the_authors_share_of_a_224_frame():
    rgba = LightProjection().watermark(224, 224)
    coverage = float(rgba[3].sum()) / (224 * 224)
    # the authors' can.png covers sum(alpha) / 224^2 = 2.75% (test_authors_parity compares with the file itself)
    assert coverage == pytest.approx(0.0275, abs=0.001)


@pytest.mark.parametrize("level", ["weak", "medium", "strong"])
@pytest.mark.parametrize("position", ["fixed", "random"])
def test_uint8_path_matches_float_path(level, position):
    img = _random_uint8((6, 3, 40, 52), seed=11)
    attack = LightProjection(level, position=position, max_offset=60, seed=4)
    params = attack.sample_params(6, 40, 52, generator=torch.Generator().manual_seed(2))
    fast = attack.apply_params(img, params)
    slow = torch.round(attack.apply_params(img.float() / 255, params) * 255).to(torch.uint8)
    assert (fast.int() - slow.int()).abs().max() <= 1
    assert torch.equal(fast, attack._apply_uint8(img, params))  # apply_params took the uint8 kernel
    single = attack.apply_params(img[2], {k: v[2:3] for k, v in params.items()})
    assert torch.equal(single, fast[2])
    assert not torch.equal(fast, img)


def test_random_intensity_draws_transparency_uniform_in_authors_range():
    attack = LightProjection("random", seed=0)
    params = attack.sample_params(2000, 32, 32, generator=torch.Generator().manual_seed(0))
    t = params["transparency"]
    assert float(t.min()) >= 0.1 - 1e-6 and float(t.max()) <= 0.9 + 1e-6
    assert float((t < 0.5).float().mean()) == pytest.approx(0.5, abs=0.04)


@pytest.mark.parametrize("shape", PROJECTION_SHAPES)
def test_procedural_shapes_are_coloured_with_transparent_surround(shape):
    rgba = projection_shape(shape, 64)
    assert rgba.shape == (4, 64, 54 if shape == "can" else 64)
    assert float(rgba[3].max()) == 1.0
    assert float(rgba[3, 0, 0]) == 0.0 or (shape == "disk" and float(rgba[3, 0, 0]) < 0.5)
    assert torch.equal(torch.round(rgba[3] * 255) / 255, rgba[3])  # 8-bit alpha as in the paper's PIL code


def test_stop_sign_is_red_octagon():
    rgba = projection_shape("stop_sign", 64)
    centre = rgba[:3, 32, 32]
    assert centre[0] > 0.7 and centre[1] < 0.2 and centre[2] < 0.2


def test_user_rgba_image_keeps_its_alpha_and_is_loaded_once(tmp_path):
    from PIL import Image

    array = np.zeros((20, 40, 4), dtype=np.uint8)
    array[:, :20] = (0, 0, 255, 255)  # left half opaque blue, right half transparent
    path = tmp_path / "logo.png"
    Image.fromarray(array, mode="RGBA").save(path)
    attack = LightProjection("strong", pattern=path, size=1.0)
    path.unlink()
    img = torch.zeros(3, 40, 40, dtype=torch.uint8)
    out = attack(img)
    wm_top = (40 - 20) // 2
    assert out[2, wm_top + 5, 5] >= 200 and out[2, wm_top + 5, 35] == 0
    assert torch.equal(pickle.loads(pickle.dumps(attack))(img), out)


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="stop_sign"):
        LightProjection(pattern="banana")
    with pytest.raises(FileNotFoundError):
        LightProjection(pattern="missing.png")
    with pytest.raises(ValueError, match="random"):
        LightProjection(position="left")
    with pytest.raises(ValueError, match="size"):
        LightProjection(size=0.0)
    with pytest.raises(ValueError, match="can"):
        LightProjection(pattern="banana")
    with pytest.raises(ValueError, match="RGBA"):
        light_projection(torch.zeros(3, 4, 4), torch.zeros(3, 2, 2), 0.5)


def test_spread_of_the_projected_light_is_in_reference_pixels():
    image = torch.full((1, 3, 128, 128), 0.2)
    options = {"model": "additive", "pattern": "disk", "size": 0.5, "strength": 0.5}  # no pixel reaches white
    sharp = LightProjection("strong", **options)(image)
    soft = LightProjection("strong", **options, spread=6.0)(image)
    assert not torch.equal(sharp, soft)

    # the disk's edge along the middle row: the spread light's 10-90% rise is 2.56 sigma wide, with sigma
    # 6 reference pixels = 3 pixels at 128, so 7.7 pixels; the sharp edge is one step
    def rise(out: torch.Tensor) -> int:
        row = out[0, 1, 64, :64]
        low, high = float(row.min()), float(row.max())
        level = (row - low) / (high - low)
        return int(((level > 0.1) & (level < 0.9)).sum())

    assert rise(sharp) <= 1 and 7 <= rise(soft) <= 9
    with pytest.raises(ValueError, match="'additive' or 'blend'"):
        LightProjection(spread=2.0)
    with pytest.raises(ValueError, match=">= 0"):
        LightProjection(model="additive", spread=-1.0)


def test_watermark_fully_outside_is_identity():
    img = _random_uint8((3, 16, 16), seed=3)
    out = LightProjection("strong", x_offset=10_000)(img)
    assert torch.equal(out, img)


@pytest.mark.parametrize("position", ["fixed", "random"])
def test_uint8_kernel_is_the_float_composite_rounded(position):
    """The uint8 kernel (PIL's integer paste formula in int16) equals the float path rounded, with per-sample
    transparencies and (random) positions, the watermark partly off the frame included."""
    images = _random_uint8((8, 3, 48, 64), 5)
    attack = LightProjection("random", position=position, max_offset=150.0, seed=2)
    params = attack.sample_params(8, 48, 64, generator=torch.Generator().manual_seed(3))
    assert len(set(params["transparency"].tolist())) == 8
    out = attack.apply_params(images, params)
    reference = attack.apply_params(images.float() / 255, params)
    assert torch.equal(out, torch.round(reference * 255).to(torch.uint8))


def test_the_projectors_gamma_turns_the_pattern_into_light_apart_from_the_cameras_curve():
    """An attacker's pattern is a frame sent to a projector: its light is pattern ** projector_gamma (the display's
    transfer) while the scene is decoded and re-encoded by the camera's sRGB curve; numpy's reference, not the
    package's decode."""
    image = torch.full((1, 3, 96, 96), 0.3)
    options = {"model": "additive", "pattern": "disk", "size": 0.5, "strength": 0.4, "gamma": None}
    emitted = LightProjection("strong", **options, projector_gamma=2.4)(image)
    captured = LightProjection("strong", **options)(image)
    watermark = LightProjection("strong", **options).watermark(96, 96)
    top, left = (96 - watermark.shape[-2]) // 2, (96 - watermark.shape[-1]) // 2
    rgb, alpha = watermark[:3].double().numpy(), watermark[3:].double().numpy()
    pattern = np.zeros((3, 96, 96))
    pattern[:, top : top + rgb.shape[1], left : left + rgb.shape[2]] = rgb * alpha

    def srgb_decode(v):
        return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)

    def srgb_encode(v):
        return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.clip(v, 1e-12, None) ** (1 / 2.4) - 0.055)

    strength = 0.4 * 1.0  # the strong level is intensity 1
    total = np.clip(srgb_decode(0.3) + strength * pattern**2.4, 0.0, 1.0)
    expected = srgb_encode(total)
    assert np.allclose(emitted[0].double().numpy(), expected, atol=2e-5)
    # decoded by the camera's curve instead, a half-bright pattern pixel is another light
    assert float((emitted - captured).abs().max()) > 0.01
    with pytest.raises(ValueError, match="'additive' or 'blend'"):
        LightProjection(projector_gamma=2.2)
    with pytest.raises(ValueError, match="> 0"):
        LightProjection(model="additive", projector_gamma=0.0)
