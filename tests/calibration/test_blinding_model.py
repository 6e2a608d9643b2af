"""The laser blinding frame model's parametrisation: glare fitted by its level where the frames show it, and the
tone curves the laser's light is composed in (``calibration/frame_models/laser_blinding.py``)."""

from __future__ import annotations

import math

import pytest
import torch

from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.laser_blinding import (
    GLARE_REFERENCE_PX,
    BlindingFrames,
    halo_amplitude,
    laser_gain,
)
from lerobot_phantom.calibration.identify import at_bound
from lerobot_phantom.transforms import physics


@pytest.mark.parametrize(
    ("level", "exponent", "scale"), [(0.02, 2.0, 8.0), (0.7, 4.5, 40.0), (3.0, 8.0, 0.3)]
)
def test_glare_level_is_the_glare_at_the_reference_distance(level, exponent, scale):
    params = {"halo_level": level, "halo_exponent": exponent, "halo_scale_ref_px": scale}
    radius = torch.tensor([0.0, GLARE_REFERENCE_PX, 4 * GLARE_REFERENCE_PX], dtype=torch.float64)
    glare = physics.power_law_halo(radius, halo_amplitude(params), exponent, scale)
    assert float(glare[1]) == pytest.approx(level, rel=1e-9)
    # and it is the transform's power law: brighter inside, fainter outside
    assert float(glare[0]) > level > float(glare[2])


def test_glare_and_tone_shoulder_build_on_linear_light():
    requires = {e.name: e.requires for e in BlindingFrames.candidates}
    assert requires["halo_power_law"] == ("linear_light_saturation",)
    assert requires["tone_shoulder"] == ("linear_light_saturation",)
    assert requires["linear_light_saturation"] == ()
    # two tone curves, not a curve and its refinement: never in one model
    excludes = {e.name: e.excludes for e in BlindingFrames.candidates}
    assert excludes["tone_shoulder"] == ("sensor_gamma",)
    assert not any(excludes[name] for name in excludes if name != "tone_shoulder")


@pytest.mark.parametrize(
    ("effects", "params"),
    [
        ({"linear_light_saturation"}, {}),
        ({"linear_light_saturation", "sensor_gamma"}, {"gamma": 2.6}),
        ({"linear_light_saturation", "tone_shoulder"}, {"shoulder": 30.0, "shoulder_exponent": 1.2}),
        (
            {"linear_light_saturation", "tone_shoulder", "sensor_gamma"},
            {"shoulder": 5.0, "shoulder_exponent": 0.8, "gamma": 1.4},
        ),
    ],
)
def test_tone_curves_invert(effects, params):
    decode, encode = BlindingFrames.tone_curve(frozenset(effects), params)
    pixels = torch.linspace(0.02, 0.98, 49, dtype=torch.float64)
    assert torch.allclose(encode(decode(pixels)), pixels, atol=1e-9)
    assert bool((decode(pixels).diff() > 0).all())


def test_a_shoulder_lifts_the_shadows_above_srgb():
    # a filmic curve stores faint light far brighter than sRGB: 1% of the full well at ~50 grey levels, not 25
    srgb_decode, _ = BlindingFrames.tone_curve(frozenset({"linear_light_saturation"}), {})
    _, shoulder_encode = BlindingFrames.tone_curve(
        frozenset({"linear_light_saturation", "tone_shoulder"}), {"shoulder": 24.0, "shoulder_exponent": 1.0}
    )
    faint = torch.tensor([0.01], dtype=torch.float64)
    assert float(shoulder_encode(faint)) > 1.8 * float(physics.encode(faint, None))
    assert float(srgb_decode(physics.encode(faint, None))) == pytest.approx(0.01, rel=1e-9)


def one_pair_problem() -> BlindingFrames:
    """A blinding frame model of one small pair: a grey scene, and a laser spot whose capture saturates its core."""
    ys, xs = torch.meshgrid(torch.arange(24.0), torch.arange(32.0), indexing="ij")
    spot = torch.exp(-((xs - 16) ** 2 + (ys - 12) ** 2) / (2 * 3.0**2)).double()
    pattern = (1.5 * spot * torch.tensor([1.0, 0.1, 0.05], dtype=torch.float64).reshape(3, 1, 1)).clamp(
        max=1.0
    )
    scene = torch.full((3, 24, 32), 0.4, dtype=torch.float64)
    return BlindingFrames([Pair("spot", scene, (scene + pattern).clamp(max=1.0), pattern, 1.0)], seed=0)


@pytest.mark.parametrize("gain", [0.18, 1.0, 30.0, 150.0])
def test_laser_gains_of_a_fraction_to_a_hundred_are_inside_the_search_range(gain):
    """The gain spans decades (about 1 for a pattern captured at the attack's power, tens for a capture exposed for
    the beam's profile): searched on its logarithm, none of these reads as pinned at a bound (on a linear 0-200
    range, 0.18 did)."""
    (spec,) = [
        p for p in one_pair_problem().param_specs(frozenset({"linear_light_saturation"})) if "gain" in p.name
    ]
    value = math.log10(gain)
    assert at_bound(value, spec.low, spec.high) is None
    assert float(laser_gain({spec.name: value})) == pytest.approx(gain)
