import pytest
import torch

from lerobot_phantom.transforms.registry import CAMERA_ATTACKS, make_attack


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
@pytest.mark.parametrize("intensity", [0.0, "weak", "strong"])
@pytest.mark.parametrize("dtype", [torch.float32, torch.float64, torch.uint8])
def test_attacks_never_modify_their_input_and_repeat_identically(name, intensity, dtype):
    generator = torch.Generator().manual_seed(0)
    image = torch.rand(2, 3, 24, 20, generator=generator)
    image = (image * 255).to(torch.uint8) if dtype == torch.uint8 else image.to(dtype)
    before = image.clone()
    attack = make_attack(name, intensity=intensity)
    params = attack.sample_params(2, 24, 20, generator=torch.Generator().manual_seed(1))
    first = attack.apply_params(image, params)
    second = attack.apply_params(image, params)  # cached patterns/profiles must not have been altered
    assert torch.equal(image, before)
    assert torch.equal(first, second)
    if intensity == 0.0:
        assert torch.equal(first, before)
