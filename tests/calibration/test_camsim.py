"""The independent camera simulator's own physics where a calibration case depends on it."""

from __future__ import annotations

import camsim as cs
import numpy as np
import pytest


def test_a_full_well_below_the_adc_maximum_clips_below_the_files_white():
    cam = cs.Camera(well_share_of_adc=0.8, tone="srgb", jpeg_quality=95)
    levels = 2**cam.adc_bits - 1
    raw = cs.sensor(np.full((cam.height, cam.width, 3), 10.0), 1.0, cam, np.random.default_rng(0))
    assert np.allclose(raw, np.round(0.8 * levels) / levels)  # saturated everywhere, at the well's code
    white = cs.encode(cs.develop(raw, cam), cam)
    expected = 255 * cs.tone_curve(np.array(np.round(0.8 * levels) / levels), cam)
    assert np.abs(white.astype(float) - expected).max() <= 1.0
    assert white.max() < 240  # sRGB(0.8) = 231: visibly below the file's maximum


def test_well_share_outside_its_range_is_rejected():
    with pytest.raises(ValueError, match=r"well_share_of_adc 1.2; valid: \(0, 1\]"):
        cs.Camera(well_share_of_adc=1.2)


def test_unknown_lost_line_mode_is_rejected():
    with pytest.raises(ValueError, match="lost_lines 'twice'; valid: banded, single"):
        cs.em_strip_pairs(np.random.default_rng(0), cs.Camera(), 2, lost_lines="twice")


@pytest.mark.parametrize("auto_exposure", [False, True])
def test_a_manual_camera_keeps_its_first_exposure_and_an_automatic_one_meters_every_scene(auto_exposure):
    cam = cs.Camera(auto_exposure=auto_exposure)
    session = cs.Session(cam)
    rng = np.random.default_rng(3)
    lit = cs.ambient_light(rng, cam.height, cam.width)
    exposures = []
    for brightness in (0.1, 0.4):  # one scene, then a four times brighter one
        _, exposure = session.clean(np.full((cam.height, cam.width, 3), brightness) * lit, rng)
        exposures.append(exposure)
    assert session.first_exposure == exposures[0]
    if auto_exposure:
        assert exposures[1] == pytest.approx(exposures[0] / 4, rel=0.05)
    else:
        assert exposures[1] == exposures[0]


def test_projection_pairs_of_a_manual_camera_share_one_exposure(monkeypatch):
    # re-metered per scene, the clean frames would be scaled against the surfaces' reflectance (which sets how much
    # projected light they return) by a factor no pair records
    exposures = []
    original = cs.capture

    def recording(*args, **kwargs):
        image, used = original(*args, **kwargs)
        exposures.append(used)
        return image, used

    monkeypatch.setattr(cs, "capture", recording)
    cs.light_projection_pairs(np.random.default_rng(5), cs.Camera(), 3)
    assert len(exposures) == 9  # clean, pattern and attacked frame per pair
    assert len(set(exposures)) == 1
