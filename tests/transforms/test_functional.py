import os

import pytest
import torch

from lerobot_phantom.transforms import functional as F
from lerobot_phantom.transforms.base import REFERENCE_SIZE
from lerobot_phantom.transforms.instruction import PAPER_SPOOFING_SUFFIX
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS, make_attack

os.environ.setdefault("HF_HUB_OFFLINE", "1")

HEIGHT, WIDTH = 37, 50


def _kernel_call(name, attack, image, params):
    """The functional kernel with the transform's own (per-sample) parameters, spelled out physically."""
    if name == "laser_blinding":
        pattern = attack.patterns_for(params["position"], HEIGHT, WIDTH, image.device)
        return F.laser_blinding(image, params["alpha"], pattern)
    if name == "light_projection":
        x_off = torch.round(params["offset"][:, 0] * (WIDTH / REFERENCE_SIZE)).long()
        y_off = torch.round(params["offset"][:, 1] * (HEIGHT / REFERENCE_SIZE)).long()
        return F.light_projection(
            image, attack.watermark(HEIGHT, WIDTH), params["transparency"], x_off, y_off
        )
    if name == "laser_color_strip":
        return F.laser_color_strip(image, params["strength"], params["color_fractions"])
    if name == "em_color_strip":
        return F.em_color_strip(
            image, params["num_stripes"], params["band_fraction"], params["next_num_stripes"], params["mix"]
        )
    if name == "em_truncation":
        return F.em_truncation(image, params["ratio"])
    if name == "ultrasound_blur":
        return F.ultrasound_blur(image, params["dx"], params["dy"], params["theta_deg"], params["scale"])
    raise AssertionError(name)


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
@pytest.mark.parametrize("dtype", [torch.uint8, torch.float32])
def test_kernel_with_per_sample_parameters_reproduces_the_transform(name, dtype):
    generator = torch.Generator().manual_seed(4)
    images = torch.randint(0, 256, (4, 3, HEIGHT, WIDTH), dtype=torch.uint8, generator=generator)
    images = images if dtype == torch.uint8 else images.to(dtype) / 255
    attack = make_attack(name, intensity="random", seed=2)
    params = attack.sample_params(4, HEIGHT, WIDTH, generator=torch.Generator().manual_seed(9))
    assert len(set(params["intensity"].tolist())) == 4
    expected = attack.apply_params(images, params)
    out = _kernel_call(name, attack, images, params)
    assert out.dtype == images.dtype and out.shape == images.shape
    torch.testing.assert_close(out, expected, atol=1e-6 if dtype != torch.uint8 else 0, rtol=0)
    assert not torch.equal(out, images)


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_apply_attack_is_the_transform_with_a_seeded_generator(name):
    image = torch.rand(2, 3, 24, 30, generator=torch.Generator().manual_seed(0))
    out, params = F.apply_attack(image, name, "random", seed=5, return_params=True)
    attack = make_attack(name, intensity="random")
    expected = attack.apply_params(
        image, attack.sample_params(2, 24, 30, generator=torch.Generator().manual_seed(5))
    )
    torch.testing.assert_close(out, expected, atol=0, rtol=0)
    torch.testing.assert_close(F.apply_attack(image, name, "random", seed=5), out, atol=0, rtol=0)
    assert params["intensity"].shape == (2,)


def test_apply_attack_accepts_per_sample_intensity_tensor_and_chw():
    image = torch.rand(3, 3, 16, 16, generator=torch.Generator().manual_seed(1))
    s = torch.tensor([0.0, 0.5, 1.0])
    out = F.apply_attack(image, "em_truncation", s)
    torch.testing.assert_close(out[0], image[0])
    torch.testing.assert_close(out[2], F.em_truncation(image[2], 0.3))
    single = F.apply_attack(image[1], "ultrasound_blur", "strong")
    assert single.shape == (3, 16, 16)


def test_apply_attack_bad_inputs():
    with pytest.raises(ValueError, match="either seed= or generator="):
        F.apply_attack(torch.zeros(3, 4, 4), "em_truncation", seed=1, generator=torch.Generator())
    with pytest.raises(TypeError, match="image tensor"):
        F.apply_attack("a task", "em_truncation")
    with pytest.raises(ValueError, match="valid attacks"):
        F.apply_attack(torch.zeros(3, 4, 4), "laser_pointer")


def test_instruction_functions_follow_the_paper_by_default():
    assert F.voice_dos("pick up the cup") == ""
    assert F.voice_dos(["a", "b c"]) == ["", ""]
    assert F.voice_spoofing("pick up the cup") == "pick up the cup" + PAPER_SPOOFING_SUFFIX
    assert F.voice_dos("pick up the cup", 0.0) == "pick up the cup"
    graded = F.voice_dos("pick up the red cup now", 0.4, mode="graded", seed=3)
    assert len(graded.split()) == 4
    assert graded == F.voice_dos("pick up the red cup now", 0.4, mode="graded", seed=3)


def test_every_camera_attack_has_a_kernel():
    for name in CAMERA_ATTACKS:
        assert callable(getattr(F, name)) and name in F.__all__
