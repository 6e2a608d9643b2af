"""``PhantomMix``: the mixing camera transform that stock ``lerobot-train`` applies through ``image_transforms``."""

import math
import os
import pickle
from collections import Counter

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import pytest
import torch

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.transforms.lerobot_registration import register_image_transforms
from lerobot_phantom.transforms.mixing import PhantomMix
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS

transforms_module = pytest.importorskip("lerobot.datasets.transforms")


def image(seed=0, shape=(3, 64, 64)):
    return torch.rand(shape, generator=torch.Generator().manual_seed(seed))


def readme_image_transforms(**kwargs):
    """What ``--dataset.image_transforms.enable=true --dataset.image_transforms.tfs='{"phantom": {"type":
    "PhantomMix", "kwargs": {...}}}'`` builds: LeRobot's defaults for everything else."""
    register_image_transforms()
    config = transforms_module.ImageTransformsConfig(
        enable=True, tfs={"phantom": transforms_module.ImageTransformConfig(type="PhantomMix", kwargs=kwargs)}
    )
    return transforms_module.ImageTransforms(config)


def attacked_fraction(transforms, calls):
    clean = image()
    return sum(not torch.equal(transforms(clean), clean) for _ in range(calls)) / calls


@pytest.mark.parametrize("rate", [0.3, 0.7])
def test_the_readme_invocation_attacks_each_view_with_probability_rate(rate):
    calls = 1500
    fraction = attacked_fraction(readme_image_transforms(rate=rate, seed=1), calls)
    assert abs(fraction - rate) <= 4 * math.sqrt(rate * (1 - rate) / calls)


def test_rate_zero_never_attacks_and_rate_one_always_changes_the_view():
    assert attacked_fraction(readme_image_transforms(rate=0.0), 100) == 0.0
    # every attack changes a 64x64 view (on a tiny one, ultrasound blur can scale below a pixel)
    assert attacked_fraction(readme_image_transforms(rate=1.0), 300) == 1.0


def test_defaults_and_checks_are_phantom_configs():
    assert PhantomMix().config == PhantomConfig()
    assert sorted(PhantomMix().attacks) == sorted(CAMERA_ATTACKS)
    with pytest.raises(ValueError, match=r"--phantom\.rate must be a number in \[0, 1\]"):
        PhantomMix(rate=1.5)
    with pytest.raises(ValueError, match="valid attacks: laser_blinding"):
        PhantomMix(attacks=["laser_blinding", "laser_pointer"])
    with pytest.raises(ValueError, match=r"camera attacks .*voice_dos"):
        PhantomMix(attacks=["laser_blinding", "voice_dos"])


def drawn(mix, calls):
    return [mix.make_params([image()]) for _ in range(calls)]


def test_attacks_are_drawn_with_their_weights():
    calls = 2000
    counts = Counter(p["attack"] for p in drawn(PhantomMix(rate=1.0, seed=2), calls))
    assert set(counts) == set(CAMERA_ATTACKS)
    expected = calls / len(CAMERA_ATTACKS)
    assert all(abs(n - expected) <= 4 * math.sqrt(expected) for n in counts.values())
    weighted = Counter(
        p["attack"]
        for p in drawn(
            PhantomMix(rate=1.0, attacks=["laser_blinding", "em_truncation"], weights=[3, 1]), calls
        )
    )
    assert abs(weighted["laser_blinding"] / calls - 0.75) <= 4 * math.sqrt(0.75 * 0.25 / calls)


def test_intensity_is_drawn_as_the_attack_draws_it():
    strong = drawn(PhantomMix(rate=1.0, intensity="strong"), 50)
    assert all(float(p["params"]["intensity"]) == 1.0 for p in strong)
    ranged = torch.cat(
        [p["params"]["intensity"] for p in drawn(PhantomMix(rate=1.0, intensity="0.2:0.4"), 200)]
    )
    assert float(ranged.min()) >= 0.2 and float(ranged.max()) <= 0.4 and float(ranged.std()) > 0.03


def test_the_frames_of_one_call_share_one_attack():
    frame = image()
    stack = frame.expand(4, -1, -1, -1).clone()  # a delta_timestamps stack of identical frames
    out = PhantomMix(rate=1.0, intensity="random", seed=3)(stack)
    assert not torch.equal(out[0], frame)
    assert all(torch.equal(out[0], out[t]) for t in range(1, 4))


def test_same_seed_same_views_and_pickling_keeps_the_stream():
    a, b = PhantomMix(rate=0.5, seed=4), PhantomMix(rate=0.5, seed=4)
    views = [image(i) for i in range(20)]
    assert all(torch.equal(a(v), b(v)) for v in views)
    clone = pickle.loads(pickle.dumps(a))
    assert all(torch.equal(clone(v), a(v)) for v in views)
