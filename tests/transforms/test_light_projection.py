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
    attack = LightProjection(size=0.5)
    assert attack.watermark(96, 128).shape == (4, 48, 48)
    assert attack.watermark(480, 640).shape == (4, 240, 240)
    assert attack.watermark(96, 128) is attack.watermark(96, 128)


@pytest.mark.parametrize("shape", PROJECTION_SHAPES)
def test_procedural_shapes_are_coloured_with_transparent_surround(shape):
    rgba = projection_shape(shape, 64)
    assert rgba.shape == (4, 64, 64)
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
    with pytest.raises(ValueError, match="RGBA"):
        light_projection(torch.zeros(3, 4, 4), torch.zeros(3, 2, 2), 0.5)


def test_watermark_fully_outside_is_identity():
    img = _random_uint8((3, 16, 16), seed=3)
    out = LightProjection("strong", x_offset=10_000)(img)
    assert torch.equal(out, img)
