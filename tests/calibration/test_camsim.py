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


def test_the_colour_correction_keeps_grey_grey_and_takes_the_filters_overlap_back_out():
    rng = np.random.default_rng(4)
    ccm = cs.random_ccm(rng)
    matrix = np.reshape(ccm, (3, 3))
    assert np.allclose(matrix.sum(1), 1.0) and np.all(matrix[~np.eye(3, dtype=bool)] <= 0.0)
    plain, corrected = (
        cs.Camera(tone="power", tone_gamma=1.0),
        cs.Camera(tone="power", tone_gamma=1.0, ccm=ccm),
    )
    grey = cs.mosaic(np.full((8, 8, 3), 0.4))
    assert np.allclose(cs.develop(grey, corrected), cs.develop(grey, plain))
    # a pure red seen through overlapping filters (some of it in green and blue) comes out more saturated
    overlapped = np.zeros((8, 8, 3))
    overlapped[..., 0], overlapped[..., 1:] = 0.5, 0.1
    red = cs.develop(cs.mosaic(overlapped), corrected)[4, 4]
    assert red[0] > 0.5 and np.all(red[1:] < 0.1)


def test_a_colour_correction_that_does_not_keep_white_is_rejected():
    with pytest.raises(ValueError, match="rows sum to 1"):
        cs.Camera(ccm=(1.2, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0))


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


@pytest.mark.parametrize("looks", [1, 4])
def test_speckle_has_mean_one_and_the_contrast_of_its_looks(looks):
    # fully developed speckle is exponential (contrast 1); the sum of `looks` independent patterns has 1/sqrt(looks)
    field = cs.speckle(np.random.default_rng(7), 256, 256, grain_px=1.5, looks=looks)
    assert field.min() >= 0.0
    assert field.mean() == pytest.approx(1.0, abs=1e-9)
    assert field.std() == pytest.approx(1.0 / np.sqrt(looks), rel=0.1)
    # grains, not white noise: neighbours one pixel apart correlate, ten apart do not
    centred = field - field.mean()
    near = np.mean(centred[:, 1:] * centred[:, :-1]) / centred.var()
    far = np.mean(centred[:, 10:] * centred[:, :-10]) / centred.var()
    assert near > 0.5 and abs(far) < 0.05


def blend_miss(pair, digital_alpha: float, where: np.ndarray) -> np.ndarray:
    """The attacked frame against the paper's blend of its clean frame and pattern, at the pixels ``where``."""
    a = digital_alpha * pair.intensity
    return pair.attacked[where] - ((1 - a) * pair.clean[where] + a * pair.pattern[where].astype(float))


def test_blinding_speckle_leaves_a_saturated_pattern_saturated_and_draws_nothing_without_it():
    cam = cs.Camera(jpeg_quality=97)
    plain = cs.laser_blinding_pairs(np.random.default_rng(11), cam, 3, digital_alpha=0.6)
    again = cs.laser_blinding_pairs(np.random.default_rng(11), cam, 3, digital_alpha=0.6, speckle_looks=None)
    assert all(np.array_equal(a.attacked, b.attacked) for a, b in zip(plain, again, strict=True))
    speckled = cs.laser_blinding_pairs(np.random.default_rng(11), cam, 3, digital_alpha=0.6, speckle_looks=3)
    for pair, reference in zip(speckled, plain, strict=True):
        saturated = pair.pattern == 255
        lit = (pair.pattern > 60) & ~saturated
        assert saturated.any() and lit.any()
        # clean and attacked are separate captures (noise) and compressed after the blend: a few grey levels
        assert np.median(np.abs(blend_miss(pair, 0.6, saturated))) < 8.0
        noise = np.std(blend_miss(reference, 0.6, reference.pattern > 60))
        assert noise < 8.0
        assert np.std(blend_miss(pair, 0.6, lit)) > 1.5 * noise


def test_a_dark_frame_is_the_laser_capture_without_the_laser_and_changes_no_other_draw():
    cam = cs.Camera(jpeg_quality=97)
    plain = cs.laser_blinding_pairs(np.random.default_rng(5), cam, 3, halo=True)
    dark = cs.laser_blinding_pairs(np.random.default_rng(5), cam, 3, halo=True, dark_frame=True)
    for a, b in zip(plain, dark, strict=True):
        assert a.pattern_dark is None
        assert all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("clean", "attacked", "pattern"))
    frame, pattern = dark[0].pattern_dark.astype(float), dark[0].pattern.astype(float)
    spot = np.unravel_index(np.argmax(pattern.sum(2)), pattern.shape[:2])
    # the laser's spot is in the capture and not in the dark frame; far from it, the two read the same room
    assert pattern[spot].max() > 150 and frame[spot].max() < 40
    corner = (slice(0, 6), slice(0, 6))
    assert abs(np.median(frame[corner]) - np.median(pattern[corner])) < 6
    assert all(np.array_equal(p.pattern_dark, dark[0].pattern_dark) for p in dark)


def test_pixel_slip_moves_only_the_corrupted_rows_left():
    cam = cs.Camera(jpeg_quality=97)
    plain = cs.em_strip_pairs(np.random.default_rng(2), cam, 2, paper_map=True)
    slipped = cs.em_strip_pairs(np.random.default_rng(2), cam, 2, paper_map=True, pixel_slip=3)
    # the slip draws after each frame's band: the first frame's scene and band are shared, its rows differ
    changed = np.abs(plain[0].attacked.astype(float) - slipped[0].attacked).mean(axis=(1, 2)) > 2.0
    assert changed.any() and not changed.all()


def test_the_paper_blur_path_spreads_as_a_constant_speed_path():
    # the time average of a path from 0 to d at constant speed: mean d/2, standard deviation d/sqrt(12)
    path = cs.uniform_path(10.0)
    assert abs(path.mean() - 5.0) < 1e-12
    assert abs(path.std() / (10.0 / np.sqrt(12.0)) - 1.0) < 1e-3
    assert path.min() > 0.0 and path.max() < 10.0


def test_the_triangle_wave_sweeps_its_centred_path_at_constant_speed():
    # whole cycles visit every position of [-d/2, d/2] equally often: mean 0, standard deviation d/sqrt(12), a flat
    # histogram (a sinusoid's arcsine piles up at both ends: its outer fifths would hold 59% of the time, not 40%)
    path = cs.triangle_wave_path(10.0, cycles=6.0, phase=0.3, samples=6000)
    assert path.min() >= -5.0 and path.max() <= 5.0
    assert abs(path.mean()) < 1e-9
    assert abs(path.std() / (10.0 / np.sqrt(12.0)) - 1.0) < 1e-3
    counts, _ = np.histogram(path, bins=5, range=(-5.0, 5.0))
    assert np.all(np.abs(counts / len(path) - 0.2) < 0.01)
    # a non-integer number of cycles still stays on the path and near its centre
    partial = cs.triangle_wave_path(10.0, cycles=5.4, phase=0.8)
    assert partial.min() >= -5.0 and partial.max() <= 5.0 and abs(partial.mean()) < 0.5


def test_a_defocus_disc_fills_its_diameter_evenly():
    # a uniform disc of diameter d: centred, inside radius d / 2, half its points within d / (2 sqrt 2) (half the area)
    points = cs.disc_offsets(10.0)
    radius = np.hypot(points[:, 0], points[:, 1])
    assert np.abs(points.mean(0)).max() < 0.1
    assert radius.max() <= 5.0
    assert np.mean(radius <= 5.0 / np.sqrt(2)) == pytest.approx(0.5, abs=0.02)


def test_white_balance_takes_back_the_cast_a_frame_gained_over_its_reference():
    rng = np.random.default_rng(1)
    reference = rng.uniform(0.2, 0.6, (16, 16, 3))
    cast = reference * np.array([1.3, 1.0, 0.8])  # the projected light's colour on the whole frame
    assert np.array_equal(cs.rebalanced(cast, reference, 0.0), cast)
    assert np.allclose(cs.rebalanced(reference, reference, 1.0), reference)

    def channel_ratios(image):
        means = image.reshape(-1, 3).mean(0)
        return means / means[1]

    full, half = cs.rebalanced(cast, reference, 1.0), cs.rebalanced(cast, reference, 0.5)
    assert np.allclose(
        channel_ratios(full), channel_ratios(reference)
    )  # full adaptation: the reference's balance
    # half adaptation: each channel's cast halved in the log
    assert np.allclose(
        channel_ratios(half), channel_ratios(reference) * np.sqrt(np.array([1.3, 1.0, 0.8])), rtol=1e-6
    )


def test_a_sweep_averages_light_before_the_camera_encodes_it():
    """``path="sweep"`` moves the image along the paper's one-way path during the exposure, so the camera encodes
    the averaged light; ``"linear"`` (the null) averages the encoded frame. Drawn alike, the two differ only there:
    the clean frames are the same, and under a power-law curve (concave) the encoded average of light is brighter
    than the average of encoded values (Jensen), most at the checkerboard's edges: by 0.69-2.04 grey levels over whole
    frames on these three draws."""
    cam = cs.Camera(tone="power", tone_gamma=2.2)
    for seed in range(
        3
    ):  # one pair a draw: the photon noise's draws depend on the light, so streams part after it
        (sweep,), (linear,) = (
            cs.ultrasound_blur_pairs(np.random.default_rng(seed), cam, 1, path=path, amplitude_px=12.0)
            for path in ("sweep", "linear")
        )
        np.testing.assert_array_equal(sweep.clean, linear.clean)
        assert float(np.mean(sweep.attacked.astype(float) - linear.attacked.astype(float))) > 0.3
