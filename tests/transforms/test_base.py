"""Input handling shared by every camera attack (the CameraAttack contract): bad input and odd-but-valid input."""

import os

import pytest
import torch

from lerobot_phantom.transforms.registry import ATTACK_NAMES, CAMERA_ATTACKS, get_attack_class, make_attack

os.environ.setdefault("HF_HUB_OFFLINE", "1")


# EM truncation corrupts the frame buffer's row addresses: every channel, alpha included, moves with its row.
MOVES_ALPHA_WITH_ROWS = {"em_truncation"}


def _image(shape, dtype=torch.uint8, seed=0):
    generator = torch.Generator().manual_seed(seed)
    if dtype == torch.uint8:
        return torch.randint(0, 256, shape, dtype=torch.uint8, generator=generator)
    return torch.rand(shape, generator=generator).to(dtype)


@pytest.fixture(params=CAMERA_ATTACKS)
def attack(request):
    return make_attack(request.param, intensity="strong", seed=0)


@pytest.mark.parametrize("shape", [(8,), (8, 8)])
def test_wrong_rank_is_rejected(attack, shape):
    with pytest.raises(ValueError, match=r"\(C, H, W\) or \(B, C, H, W\)"):
        attack(torch.zeros(shape))


@pytest.mark.parametrize("channels", [2, 5])
def test_unsupported_channel_count_names_the_valid_ones(attack, channels):
    with pytest.raises(ValueError, match=r"\(1, 3, 4\)"):
        attack(torch.zeros(channels, 8, 8))


def test_nan_is_rejected(attack):
    image = torch.rand(3, 8, 8)
    image[1, 2, 3] = float("nan")
    with pytest.raises(ValueError, match="NaN"):
        attack(image)


@pytest.mark.parametrize("shape", [(3, 0, 8), (0, 3, 8, 8)])
def test_empty_images_are_rejected(attack, shape):
    with pytest.raises(ValueError, match="empty"):
        attack(torch.zeros(shape))


def test_non_tensor_and_bool_images_are_rejected(attack):
    with pytest.raises(TypeError, match="dtype"):
        attack.apply_params(torch.zeros(3, 4, 4, dtype=torch.bool), attack.sample_params(1, 4, 4))
    with pytest.raises(TypeError, match=r"torch\.Tensor"):
        attack.apply_params([[0.0]], attack.sample_params(1, 4, 4))


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
@pytest.mark.parametrize("intensity", [1.5, -0.1, float("nan"), (0.8, 0.2), "extreme", "0.1:0.2:0.3"])
def test_bad_intensity_names_the_valid_values(name, intensity):
    with pytest.raises(ValueError, match="weak"):
        make_attack(name, intensity=intensity)


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_bad_per_sample_intensity_tensor(name):
    attack = make_attack(name)
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        attack.sample_params(2, 8, 8, intensity=torch.tensor([0.5, 1.2]))


def test_unknown_attack_lists_the_valid_ones():
    with pytest.raises(ValueError, match="laser_blinding") as info:
        make_attack("laser_blindness")
    for name in ATTACK_NAMES:
        assert name in str(info.value)


def test_random_range_without_generator_is_a_clear_error(attack):
    with pytest.raises(ValueError, match="Generator"):
        attack.sample_params(2, 8, 8, intensity="random")


@pytest.mark.parametrize("dtype", [torch.uint8, torch.float32, torch.float64, torch.float16])
@pytest.mark.parametrize(
    "shape",
    [
        (3, 1, 1),
        (1, 3, 1, 1),
        (3, 17, 23),
        (2, 3, 31, 9),
        (2, 2, 3, 5, 7),
        (1, 13, 11),
        (4, 12, 10),
        (2, 4, 7, 6),
    ],
)
def test_valid_inputs_keep_dtype_shape_and_alpha(attack, dtype, shape):
    image = _image(shape, dtype, seed=sum(shape))
    out = attack(image)
    assert out.shape == image.shape and out.dtype == image.dtype and out.device == image.device
    if image.shape[-3] == 4 and attack.name not in MOVES_ALPHA_WITH_ROWS:
        assert torch.equal(out[..., 3:, :, :], image[..., 3:, :, :])  # alpha channel passes through


def test_grey_image_stays_grey(attack):
    image = _image((1, 20, 24), torch.float32, seed=3)
    out = attack(image)
    assert out.shape == (1, 20, 24)


def test_input_is_never_modified_in_place(attack):
    for dtype in (torch.uint8, torch.float32):
        image = _image((2, 3, 16, 20), dtype, seed=4)
        before = image.clone()
        attack(image)
        assert torch.equal(image, before)


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_every_attack_class_carries_its_registry_name(name):
    assert get_attack_class(name).name == name


# -- torchvision v2 semantics -------------------------------------------------------------------------------
def test_image_and_video_tv_tensors_come_back_as_their_type(attack):
    from torchvision import tv_tensors

    for wrapped in (tv_tensors.Image(_image((3, 16, 16))), tv_tensors.Video(_image((2, 3, 16, 16)))):
        out = attack(wrapped)
        assert type(out) is type(wrapped)
        assert out.shape == wrapped.shape and out.dtype == wrapped.dtype
        assert not torch.equal(out.as_subclass(torch.Tensor), wrapped.as_subclass(torch.Tensor))


def test_masks_boxes_and_other_inputs_pass_through_untouched(attack):
    from torchvision import tv_tensors

    image = tv_tensors.Image(_image((3, 16, 16)))
    mask = tv_tensors.Mask(_image((16, 16)))
    boxes = tv_tensors.BoundingBoxes([[1, 2, 5, 6]], format="XYXY", canvas_size=(16, 16))
    sample = {"image": image, "mask": mask, "boxes": boxes, "label": 3, "name": "front"}
    out = attack(sample)
    assert out["mask"] is mask and out["boxes"] is boxes and out["label"] == 3 and out["name"] == "front"
    assert type(out["image"]) is tv_tensors.Image and not torch.equal(out["image"], image)
    # the mask comes first: parameters are still drawn for the image, and the mask is not attacked
    mask_out, image_out = attack(mask, image)
    assert mask_out is mask and image_out.shape == image.shape


def test_a_call_without_an_image_passes_through_and_draws_nothing(attack):
    from torchvision import tv_tensors

    mask = tv_tensors.Mask(_image((16, 16)))
    state = attack._get_generator().get_state()
    out_mask, out_text = attack(mask, "text")
    assert out_mask is mask and out_text == "text"
    assert torch.equal(attack._get_generator().get_state(), state)
