"""Every attack that composes light takes a tone curve with a highlight shoulder (``physics.ShoulderCurve``), as
``lerobot-phantom-calibrate`` fits it (``tone_shoulder``): at shoulder 0 it is the power law the attack took before,
and a shoulder changes what the light adds where the curve bends."""

from __future__ import annotations

import pickle

import pytest
import torch

from lerobot_phantom.transforms.laser_blinding import LaserBlinding
from lerobot_phantom.transforms.laser_color_strip import LaserColorStrip
from lerobot_phantom.transforms.light_projection import LightProjection
from lerobot_phantom.transforms.ultrasound_blur import UltrasoundBlur

# each attack in a model that composes light under a power law of 2.2
ATTACKS = {
    "ultrasound_blur": (UltrasoundBlur, {"path": "sinusoidal"}),
    "laser_color_strip": (
        LaserColorStrip,
        {
            "model": "rolling_shutter",
            "frequency_hz": 0.5,
            "duty": 0.3,
            "exposure_s": 0.05,
            "row_time_s": 1 / 48,
        },
    ),
    "light_projection": (
        LightProjection,
        {"model": "additive", "pattern": "disk", "size": 0.5, "strength": 0.5},
    ),
    "laser_blinding": (LaserBlinding, {"model": "physical", "gain": 0.5}),
}


def _image() -> torch.Tensor:
    # a horizontal ramp from dark to near white, with texture for the blur to average
    ramp = torch.linspace(0.05, 0.95, 48).expand(3, 48, 48)
    texture = 0.04 * torch.rand(3, 48, 48, generator=torch.Generator().manual_seed(1))
    return (ramp + texture).clamp(0, 1)


@pytest.mark.parametrize("name", ATTACKS)
def test_a_shoulder_of_zero_is_the_power_law_and_a_shoulder_changes_the_attack(name):
    kind, options = ATTACKS[name]
    image = _image()

    def attacked(**tone):
        return kind("strong", **options, gamma=2.2, seed=3, **tone)(image)

    power_law = attacked()
    assert torch.allclose(attacked(shoulder=0.0, shoulder_exponent=1.7), power_law, atol=1e-5)
    shouldered = kind("strong", **options, gamma=2.2, shoulder=20.0, shoulder_exponent=1.3, seed=3)
    # the curve is kept through pickling (DataLoader workers)
    assert pickle.loads(pickle.dumps(shouldered))(image).sub(power_law).abs().max() > 0.01


@pytest.mark.parametrize(
    ("kind", "options", "needs"),
    [
        (LightProjection, {}, "model='additive' or 'blend'"),
        (LaserColorStrip, {}, "rolling_shutter"),
        (UltrasoundBlur, {"rotation_deg": 5.0}, "linear blur only"),
        # the paper's blend ignored every physical option; now it names them
        (LaserBlinding, {"gain": 2.0}, r"\['gain', 'shoulder'\] are the physical model's"),
    ],
)
def test_a_shoulder_where_the_attack_composes_no_light_is_refused(kind, options, needs):
    with pytest.raises(ValueError, match=needs):
        kind(shoulder=4.0, **options)


def test_the_laser_physics_builds_its_tone_curve_once_and_a_replaced_copy_its_own():
    """``LaserPhysics`` checks and builds its tone curve when made (every batch read it again until session 88);
    a copy with other options gets the curve of those, and the curve is no option of ``LaserBlinding``."""
    import dataclasses

    from lerobot_phantom.transforms import physics
    from lerobot_phantom.transforms.laser_blinding import LaserPhysics

    options = LaserPhysics(gamma=1.0, shoulder=3.0, shoulder_exponent=0.5)
    assert options.tone is options.tone
    assert options.tone == physics.ShoulderCurve(3.0, 0.5, 1.0)
    assert pickle.loads(pickle.dumps(options)).tone == options.tone
    assert dataclasses.replace(options, shoulder=None, shoulder_exponent=1.0).tone == 1.0
    with pytest.raises(TypeError, match="unknown options"):
        LaserBlinding(model="physical", _tone=2.2)
