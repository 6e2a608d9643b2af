"""``make_attack(name, calibration=DIR)``: attacks running the calibrated physics, tested like the others."""

from __future__ import annotations

import json
import os

import pytest
import torch

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from lerobot_phantom.transforms.calibrated import calibrated_options
from lerobot_phantom.transforms.registry import (
    CAMERA_ATTACKS,
    make_attack,
    make_attacks,
)

CALIBRATED = {
    "laser_blinding": {
        "model": "physical",
        "gain": 1.5,
        "glare_amplitude": 0.3,
        "glare_exponent": 2.0,
        "glare_scale_ref_px": 12.0,
        "auto_exposure": 2.0,
        "gamma": None,
    },
    "light_projection": {
        "model": "additive",
        "strength": 0.6,
        "albedo": True,
        "reflectance_floor": 0.2,
        "crosstalk": [[0.8, 0.1, 0.0], [0.1, 0.7, 0.1], [0.0, 0.2, 0.9]],
        # the stop sign's form: a shouldered tone curve under no display gamma, the projector's own gamma
        "gamma": 1.0,
        "shoulder": 2.2,
        "shoulder_exponent": 0.5,
        "projector_gamma": 2.2,
    },
    "laser_color_strip": {
        "model": "rolling_shutter",
        "row_time_s": 4.8e-5,
        "frame_rows": 720,
        "integration_offset_s": 5e-4,
        "edge_threshold": 0.08,
    },
    "ultrasound_blur": {"path": "sinusoidal", "gamma": 2.2},
    "em_color_strip": {"model": "bayer_phase_flip", "gain": 1.8, "offset": 0.05},
    "em_truncation": {
        "ratio_per_intensity": 0.25,
        "ratio_per_intensity_spread": 0.02,
        "ratio_jitter": 0.01,
        "free_band_position": True,
    },
}


def write(tmp_path, name, kwargs):
    folder = tmp_path / name
    folder.mkdir()
    (folder / "calibrated.json").write_text(json.dumps({"format": 1, "attack": name, "kwargs": kwargs}))
    return folder


def scene(batch=2, height=48, width=64, seed=0):
    g = torch.Generator().manual_seed(seed)
    base = torch.rand(batch, 3, height // 8, width // 8, generator=g)
    return torch.nn.functional.interpolate(base, size=(height, width), mode="nearest")


@pytest.mark.parametrize("name", sorted(CALIBRATED))
def test_calibrated_attack_identity_dtype_shape_and_difference(tmp_path, name):
    calibration = write(tmp_path, name, CALIBRATED[name])
    attack = make_attack(name, intensity=1.0, calibration=str(calibration), seed=0)
    other = next(n for n in sorted(CALIBRATED) if n != name)
    with pytest.raises(ValueError, match=rf"calibrates \['{name}'\], not '{other}'"):
        make_attack(other, intensity=1.0, calibration=str(calibration))
    x = scene()
    # identity at s = 0
    zero = make_attack(name, intensity=0.0, calibration=str(calibration), seed=0)
    assert torch.allclose(zero(x), x, atol=1e-5)
    as_uint8 = (x[0] * 255).round().to(torch.uint8)
    assert torch.equal(zero(as_uint8), as_uint8)
    # dtype and shape preserved
    out = attack(x)
    assert out.shape == x.shape and out.dtype == x.dtype
    out8 = attack(as_uint8)
    assert out8.shape == as_uint8.shape and out8.dtype == torch.uint8
    # the calibrated physics differs from the paper's simulation and from the clean image
    params = attack.sample_params(2, 48, 64, generator=torch.Generator().manual_seed(1))
    paper = make_attack(name, intensity=1.0, seed=0)
    paper_params = paper.sample_params(2, 48, 64, generator=torch.Generator().manual_seed(1))
    calibrated_out = attack.apply_params(x, params)
    assert (calibrated_out - x).abs().mean() > 0.01
    assert (calibrated_out - paper.apply_params(x, paper_params)).abs().mean() > 0.005


def test_explicit_kwargs_override_the_calibration(tmp_path):
    calibration = write(tmp_path, "em_color_strip", CALIBRATED["em_color_strip"])
    attack = make_attack("em_color_strip", intensity=1.0, calibration=str(calibration), model="paper")
    assert attack.model == "paper"


def test_a_calibration_set_calibrates_its_attacks_and_leaves_the_others_paper(tmp_path):
    # What several `lerobot-phantom-calibrate --out SET/<attack>` runs write, for training that mixes attacks.
    calibration_set = tmp_path / "set"
    calibration_set.mkdir()
    for name in ("laser_blinding", "light_projection"):
        write(calibration_set, name, CALIBRATED[name])
    assert list(calibrated_options(CAMERA_ATTACKS, str(calibration_set))) == [
        "laser_blinding",
        "light_projection",
    ]
    attacks = make_attacks(CAMERA_ATTACKS, intensity=1.0, calibration=str(calibration_set))
    assert list(attacks) == list(CAMERA_ATTACKS)
    assert attacks["laser_blinding"].model == "physical"
    assert attacks["light_projection"].model == "additive"
    assert attacks["light_projection"].physical["projector_gamma"] == 2.2
    x = scene()
    for name in ("em_truncation", "ultrasound_blur", "laser_color_strip"):
        paper = make_attack(name, intensity=1.0)
        params = paper.sample_params(2, 48, 64, generator=torch.Generator().manual_seed(2))
        assert torch.equal(attacks[name].apply_params(x, params), paper.apply_params(x, params)), name
    # One attack asked for explicitly must be calibrated by the set; the error names what the set holds.
    with pytest.raises(
        ValueError, match=r"calibrates \['laser_blinding', 'light_projection'\], not 'em_truncation'"
    ):
        make_attack("em_truncation", calibration=str(calibration_set))
    with pytest.raises(ValueError, match="not any of em_truncation, voice_dos;"):
        make_attacks(["em_truncation", "voice_dos"], calibration=str(calibration_set))


def test_a_calibration_set_refuses_a_misfiled_or_missing_calibration(tmp_path):
    calibration_set = tmp_path / "set"
    calibration_set.mkdir()
    misfiled = write(calibration_set, "light_projection", CALIBRATED["light_projection"])
    payload = {"format": 1, "attack": "laser_blinding", "kwargs": CALIBRATED["laser_blinding"]}
    (misfiled / "calibrated.json").write_text(json.dumps(payload))
    with pytest.raises(ValueError, match="move it to"):
        make_attacks(CAMERA_ATTACKS, calibration=str(calibration_set))
    (misfiled / "calibrated.json").unlink()
    with pytest.raises(FileNotFoundError, match="--out"):
        make_attacks(CAMERA_ATTACKS, calibration=str(calibration_set))


def test_bad_model_names_are_rejected(tmp_path):
    for name, kwargs in (
        ("laser_blinding", {"model": "laser"}),
        ("light_projection", {"model": "glow"}),
        ("laser_color_strip", {"model": "global_shutter"}),
        ("em_color_strip", {"model": "random"}),
        ("ultrasound_blur", {"path": "zigzag"}),
    ):
        with pytest.raises(ValueError, match="valid"):
            make_attack(name, **kwargs)


def test_calibration_to_attack_end_to_end(tmp_path):
    import calibration_testkit as kit

    from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

    measured = tmp_path / "measured"
    measured.mkdir()
    kit.render_em_color_strip(measured, {"bayer_phase_flip"}, seed=3)
    report = calibrate(
        CalibrateConfig(attack="em_color_strip", measured=str(measured), out=str(tmp_path / "out"))
    )
    attack = make_attack("em_color_strip", intensity=0.5, calibration=str(tmp_path / "out"))
    assert attack.model == "bayer_phase_flip"
    assert attack.bayer["gain"] == pytest.approx(report["extended"]["params"]["gain"])
    x = scene(1)
    out = attack(x)
    changed_rows = ((out - x).abs().amax(dim=(0, 1, 3)) > 1e-4).nonzero().flatten()
    assert len(changed_rows) > 0 and int(changed_rows.min()) > 0
    # the flip runs to the frame's end: every row after the first changed one may differ, none before
    assert int(changed_rows.max()) >= x.shape[-2] - 8


def test_a_calibrated_demosaic_reaches_the_paper_bands(tmp_path):
    """``bayer_demosaic`` named on the paper's bands: calibrated.json carries the tile and the fitted colours, and
    the attack mis-decodes its bands through the demosaic with them."""
    from lerobot_phantom.transforms.em_color_strip import EMColorStrip

    kwargs = {"gain": 1.1, "offset": 0.02, "demosaic_pattern": "GBRG"}
    attack = make_attack(
        "em_color_strip", intensity=0.7, calibration=str(write(tmp_path, "em_color_strip", kwargs)), seed=4
    )
    assert (attack.model, attack.demosaic_pattern, attack.bayer["gain"]) == ("paper", "GBRG", 1.1)
    x = scene(2)
    torch.testing.assert_close(attack(x), EMColorStrip(0.7, seed=4, **kwargs)(x))
    assert not torch.allclose(attack(x), EMColorStrip(0.7, seed=4)(x))
