"""Sensor-physics kernels: identities, limits and closed forms that could each fail."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import torch

from lerobot_phantom.transforms import physics


def test_srgb_round_trip_and_reference_points():
    x = torch.linspace(0, 1, 101, dtype=torch.float64)
    assert torch.allclose(physics.linear_to_srgb(physics.srgb_to_linear(x)), x, atol=1e-9)
    # sRGB mid-grey 0.5 is ~21.4% linear light (IEC 61966-2-1)
    assert float(physics.srgb_to_linear(torch.tensor(0.5))) == pytest.approx(0.2140, abs=1e-3)


def test_power_gamma_round_trip():
    x = torch.rand(4, 3, 5, 5, generator=torch.Generator().manual_seed(0), dtype=torch.float64)
    assert torch.allclose(physics.encode(physics.decode(x, 2.2), 2.2), x, atol=1e-9)


def test_linear_light_injection_adds_clips_and_auto_exposure_darkens():
    scene = torch.full((1, 3, 4, 4), 0.5)
    none = physics.inject_linear_light(scene, torch.zeros_like(scene))
    assert torch.allclose(none, scene, atol=1e-6)
    strong = physics.inject_linear_light(scene, torch.full_like(scene, 5.0))
    assert torch.allclose(strong, torch.ones_like(scene))  # saturates at white
    light = torch.zeros_like(scene)
    light[..., 0, 0] = 0.5
    plain = physics.inject_linear_light(scene, light)
    darker = physics.inject_linear_light(scene, light, auto_exposure=10.0)
    assert (darker[..., 3, 3] < plain[..., 3, 3]).all()  # far from the light, the scene got darker


def test_a_colour_correction_mixes_the_raw_channels_after_they_clip():
    scene = torch.rand(2, 3, 6, 6, generator=torch.Generator().manual_seed(3), dtype=torch.float64) * 0.6
    matrix = torch.tensor([[1.6, -0.3, -0.3], [-0.2, 1.5, -0.3], [-0.1, -0.4, 1.5]], dtype=torch.float64)
    # no light: the scene goes to the raw channels and back unchanged; the identity is the model without a matrix
    unlit = physics.inject_linear_light(scene, torch.zeros_like(scene), colour_correction=matrix)
    assert torch.allclose(unlit, scene, atol=1e-9)
    red = torch.zeros_like(scene)
    red[:, 0] = 3.0
    plain = physics.inject_linear_light(scene, red)
    assert torch.allclose(
        physics.inject_linear_light(scene, red, colour_correction=torch.eye(3, dtype=torch.float64)), plain
    )
    # a red overload clips the raw red channel at the full well, and the matrix then takes that full well's share
    # out of green and blue: they end darker than the scene, which light added to the stored channels never does
    mixed = physics.inject_linear_light(scene, red, colour_correction=matrix)
    raw = physics.mix_channels(torch.linalg.inv(matrix), physics.decode(scene, None))
    expected_green = (-0.2 + 1.5 * raw[:, 1] - 0.3 * raw[:, 2]).clamp(0, 1)
    assert torch.allclose(physics.decode(mixed, None)[:, 1], expected_green, atol=1e-9)
    assert (mixed[:, 1:] < scene[:, 1:] + 1e-9).all() and (mixed[:, 1:] < scene[:, 1:] - 0.01).any()
    assert torch.allclose(plain[:, 1:], scene[:, 1:])


def test_laser_injection_adds_the_lasers_light_and_glare():
    scene = torch.full((2, 3, 16, 16), 0.3)
    pattern = torch.zeros(1, 3, 16, 16)
    pattern[:, :, 7:9, 7:9] = 1.0
    off = physics.laser_injection(scene, pattern, torch.zeros(2))
    assert torch.allclose(off, scene, atol=1e-5)
    on = physics.laser_injection(scene, pattern, torch.tensor([0.5, 2.0]))
    assert (on[1, :, 8, 8] > 0.999).all() and (on[0, :, 8, 8] < 0.9).all()  # the stronger laser saturates
    assert torch.allclose(on[:, :, 0, 0], scene[:, :, 0, 0], atol=1e-5)  # no light, no change
    glare = physics.laser_injection(
        scene,
        pattern,
        torch.tensor([1.0, 1.0]),
        centre=torch.tensor([[8.0, 8.0], [8.0, 8.0]]),
        color=torch.tensor([0.0, 1.0, 0.0]),
        halo_amplitude=5.0,
        halo_scale_px=2.0,
    )
    assert glare[0, 1, 0, 0] > on[0, 1, 0, 0] + 0.05 and glare[0, 0, 0, 0] == pytest.approx(0.3, abs=1e-5)
    dimmed = physics.laser_injection(scene, pattern, torch.tensor([1.0, 1.0]), auto_exposure=50.0)
    assert (dimmed[:, :, 0, 0] < 0.25).all()


def test_a_captures_glare_is_added_back_where_it_measured_the_laser_and_the_larger_counts_elsewhere():
    """``measured``: the capture's light holds the glare already, less the share its dark level took out (the glare
    at ``dark_radius_px``); where it measured nothing, its continued beam and the glare estimate one light."""
    scene = torch.zeros(1, 3, 9, 9, dtype=torch.float64)
    light = torch.zeros(1, 3, 9, 9, dtype=torch.float64)
    light[:, :, 3:6, 3:6] = 0.2
    light[:, :, 0, 0] = 0.05  # a continued beam far out, brighter than the glare there
    measured = torch.zeros(9, 9, dtype=torch.bool)
    measured[3:6, 3:6] = True
    centre = torch.tensor([[4.0, 4.0]], dtype=torch.float64)
    colour = torch.tensor([1.0, 0.5, 0.0], dtype=torch.float64)
    options = {"halo_amplitude": 0.1, "halo_exponent": 2.0, "halo_scale_px": 1.0, "gamma": 1.0}
    out = physics.laser_injection(
        scene, light, 1.0, centre=centre, color=colour, measured=measured, dark_radius_px=6.0, **options
    )
    radius = physics.radial_distance(9, 9, centre, dtype=torch.float64)
    glare = physics.power_law_halo(radius, 0.1, 2.0, 1.0) * colour.reshape(1, 3, 1, 1)
    at_dark_radius = 0.1 * (1 + 6.0) ** -2.0 * colour.reshape(1, 3, 1, 1)
    torch.testing.assert_close(out[:, :, 4, 4], (0.2 + at_dark_radius)[:, :, 0, 0])
    torch.testing.assert_close(out[:, :, 0, 0], torch.maximum(light, glare)[:, :, 0, 0])
    torch.testing.assert_close(out[:, :, 8, 8], glare[:, :, 8, 8])
    everywhere = physics.laser_injection(scene, light, 1.0, centre=centre, color=colour, **options)
    torch.testing.assert_close(everywhere, (light + glare).clamp(max=1.0))


def test_the_meter_exposes_the_blinded_frame_to_read_as_the_clean_one():
    """``metered_exposure``: the clipped mean of the blinded light at ``k`` equals the clean frame's; with
    ``meter_power`` the frame's exposure scales by ``k ** a`` (a = 1: the meter's reading restored)."""
    generator = torch.Generator().manual_seed(8)
    scene = torch.rand(3, 3, 20, 20, generator=generator, dtype=torch.float64) * 0.6
    light = torch.zeros_like(scene)
    light[:, :, 5:12, 5:12] = torch.tensor([0.5, 3.0, 40.0], dtype=torch.float64).reshape(3, 1, 1, 1)
    total = (scene + light).mean(1).flatten(1)
    k = physics.metered_exposure(total, scene.mean(1).flatten(1))
    assert (k < 1).all() and k[0] > k[1] > k[2]
    reading = torch.minimum(k[:, None] * total, torch.ones_like(total)).mean(1)
    torch.testing.assert_close(reading, scene.mean(1).flatten(1).clamp(max=1.0).mean(1), atol=1e-9, rtol=0)
    metered = physics.inject_linear_light(scene, light, meter_power=1.0, gamma=1.0)
    torch.testing.assert_close(metered, ((scene + light) * k.reshape(-1, 1, 1, 1)).clamp(0.0, 1.0))
    half = physics.inject_linear_light(scene, light, meter_power=0.5, gamma=1.0)
    torch.testing.assert_close(half, ((scene + light) * k.sqrt().reshape(-1, 1, 1, 1)).clamp(0.0, 1.0))
    with pytest.raises(ValueError, match="two auto-exposures"):
        physics.inject_linear_light(scene, light, meter_power=1.0, auto_exposure=2.0)


def test_a_luminance_meter_weighs_each_channel_as_rec_709():
    """``meter_light``: the channel mean, or the luminance (0.2126, 0.7152, 0.0722) along any channel axis; a meter
    of luminance reads a blue laser's light at a fifth of the channel mean's weight against a grey scene, so it
    darkens the frame less; an unknown reading is refused, naming the valid ones."""
    generator = torch.Generator().manual_seed(3)
    light = torch.rand(2, 3, 4, 5, generator=generator, dtype=torch.float64)
    expected = 0.2126 * light[:, 0] + 0.7152 * light[:, 1] + 0.0722 * light[:, 2]
    torch.testing.assert_close(physics.meter_light(light, "luminance", -3), expected)
    torch.testing.assert_close(physics.meter_light(light.movedim(1, -1), "luminance", -1), expected)
    torch.testing.assert_close(physics.meter_light(light, "channel_mean", 1), light.mean(1))
    scene = torch.full((1, 3, 32, 32), 0.3, dtype=torch.float64)
    blue = torch.zeros_like(scene)
    blue[0, 2, 8:24, 8:24] = 20.0

    def corner(reads: str) -> float:
        frame = physics.inject_linear_light(scene, blue, meter_power=1.0, meter_reads=reads, gamma=1.0)
        return float(frame[0, 0, 0, 0])

    assert corner("channel_mean") < corner("luminance") < 0.3
    # the exposure k (an unlit pixel's 0.3 k) reads the blinded light's clipped luminance as the clean frame's
    k = corner("luminance") / 0.3
    luminance = physics.meter_light(scene + blue, "luminance", -3).flatten(-2)[
        ..., physics.meter_pixels(32, 32)
    ]
    assert float((k * luminance).clamp(max=1.0).mean()) == pytest.approx(0.3, abs=1e-9)
    with pytest.raises(ValueError, match="meter_reads 'luma'; valid: channel_mean, luminance"):
        physics.inject_linear_light(scene, blue, meter_power=1.0, meter_reads="luma")


def test_the_meter_reads_a_regular_sample_of_the_frame():
    """``meter_pixels``: 1024 distinct pixels of a 224 x 224 frame, every row band and column band holding its share
    (within one pixel of it), every pixel of a frame of no more; the attack's meter reads those pixels only, so
    light on a pixel outside them changes no frame's exposure and light on one of them darkens the frame."""
    read = physics.meter_pixels(224, 224)
    assert len(read) == 1024 == len(read.unique())
    for counts in (
        torch.bincount(read // 224 // 28, minlength=8),
        torch.bincount(read % 224 // 28, minlength=8),
    ):
        assert int(counts.min()) >= 127 and int(counts.max()) <= 129
    torch.testing.assert_close(physics.meter_pixels(20, 30), torch.arange(600))
    scene = torch.full((1, 3, 64, 48), 0.3, dtype=torch.float64)
    spots = physics.meter_pixels(64, 48)
    unread = int(torch.isin(torch.arange(64 * 48), spots, invert=True).nonzero()[0])

    def metered_with_light_at(pixel: int) -> torch.Tensor:
        light = torch.zeros_like(scene)
        light[0, :, pixel // 48, pixel % 48] = 50.0
        return physics.inject_linear_light(scene, light, meter_power=1.0, gamma=1.0)

    assert float(metered_with_light_at(unread)[0, 0, 63, 0]) == pytest.approx(0.3, abs=1e-12)
    assert float(metered_with_light_at(int(spots[7]))[0, 0, 63, 0]) < 0.2995


def test_the_meter_stops_only_at_its_root():
    """Light spread over three decades clips piece by piece: Newton's first step runs to the lower bound and the next
    four climb back across the clipped pixels' breakpoints; the early stop waits until a step moves ``k`` by
    rounding only, so the reading equals the clean frame's (stopping once a step is under 2e-3 would leave 2.4e-4)."""
    total = torch.logspace(-1, 2, 400, dtype=torch.float64)[None]
    scene = torch.full_like(total, 0.3)
    k = physics.metered_exposure(total, scene)
    reading = torch.minimum(k[:, None] * total, torch.ones_like(total)).mean(1)
    torch.testing.assert_close(reading, torch.tensor([0.3], dtype=torch.float64), atol=1e-12, rtol=0)
    assert physics.metered_exposure(total, scene, steps=4) != k  # the root needs the fifth step


def test_halo_is_power_law_and_saturation_radius_solves_profile():
    r = torch.tensor([10.0, 20.0, 40.0], dtype=torch.float64)
    halo = physics.power_law_halo(r, 1.0, 2.0, 1e-6)  # r >> scale: pure r^-2
    assert float(halo[0] / halo[1]) == pytest.approx(4.0, rel=1e-4)
    radius = physics.saturation_radius(10.0, 5.0)
    value = 10.0 * math.exp(-0.5 * (radius / 5.0) ** 2)
    assert value == pytest.approx(1.0, rel=1e-6)
    assert physics.saturation_radius(0.5, 5.0) == 0.0


def test_projected_light_on_black_surface_vanishes_with_albedo():
    black = torch.zeros(1, 3, 2, 2)
    pattern = torch.ones(1, 3, 2, 2)
    assert torch.allclose(physics.project_light(black, pattern, 1.0, albedo=True), black)
    assert (physics.project_light(black, pattern, 1.0, albedo=True, reflectance_floor=0.2) > 0.1).all()
    lit = physics.project_light(black, pattern, 0.2, albedo=False)
    assert torch.allclose(lit, torch.full_like(lit, 0.2))  # gamma 1: composes the encoded values
    lit_srgb = physics.project_light(black, pattern, 0.2, albedo=False, gamma=None)
    assert (lit_srgb > 0.45).all()  # 20% linear light is ~48% in sRGB
    swap = torch.tensor([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    red = torch.zeros(1, 3, 1, 1)
    red[:, 0] = 1.0
    out = physics.project_light(torch.zeros(1, 3, 1, 1), red, 0.5, albedo=False, crosstalk=swap)
    assert (
        float(out[0, 1, 0, 0]) == pytest.approx(0.5, abs=1e-5) and float(out[0, 0, 0, 0]) < 1e-6
    )  # red light seen in the green channel


@pytest.mark.parametrize("sigma", [0.6, 1.3, 2.5])
def test_gaussian_spread_is_scipys_gaussian_filter_with_edges_repeated(sigma):
    from scipy import ndimage

    light = torch.rand(2, 3, 17, 23, generator=torch.Generator().manual_seed(7), dtype=torch.float64)
    spread = physics.gaussian_spread(light, sigma)
    expected = ndimage.gaussian_filter(
        light.numpy(), sigma=(0, 0, sigma, sigma), mode="nearest", truncate=3.0
    )
    # scipy truncates at int(3 sigma + 0.5) pixels, the kernel here at ceil(3 sigma): the tails differ by < 0.3%
    assert torch.allclose(spread, torch.from_numpy(expected), atol=3e-3)
    assert torch.allclose(physics.gaussian_spread(light, 0.0, radius=4), light)  # no spread: the identity


def test_gaussian_spread_per_image_and_its_derivative_in_sigma():
    spot = torch.zeros(2, 1, 9, 9, dtype=torch.float64)
    spot[:, :, 4, 4] = 1.0
    spread = physics.gaussian_spread(spot, torch.tensor([0.0, 1.0], dtype=torch.float64), radius=4)
    assert float(spread[0, 0, 4, 4]) == 1.0 and float(spread[1, 0, 4, 4]) < 0.2
    assert torch.allclose(spread.sum(dim=(2, 3)), torch.ones(2, 1, dtype=torch.float64))  # light is conserved
    # the peak of a 2-D Gaussian is 1 / (2 pi sigma^2): d/dsigma = -1 / (pi sigma^3)
    peak = torch.func.jacfwd(lambda s: physics.gaussian_spread(spot[:1], s, radius=4)[0, 0, 4, 4])
    assert float(peak(torch.tensor(1.0, dtype=torch.float64))) == pytest.approx(-1.0 / math.pi, rel=0.01)


def test_projected_light_spreads_before_it_meets_the_surface():
    surface = torch.full((1, 3, 16, 16), 0.2)
    pattern = torch.zeros(1, 3, 16, 16)
    pattern[..., 8:] = 1.0  # a sharp vertical edge
    sharp = physics.project_light(surface, pattern, 0.5)
    soft = physics.project_light(surface, pattern, 0.5, spread_px=1.5)
    assert torch.equal(physics.project_light(surface, pattern, 0.5, spread_px=0.0), sharp)
    # light crosses the edge: the dark side brightens, the lit side dims, far from it nothing changes
    assert float(soft[0, 0, 8, 7]) > 0.3 and float(soft[0, 0, 8, 8]) < 0.6
    assert torch.allclose(soft[..., :3], sharp[..., :3]) and torch.allclose(soft[..., 13:], sharp[..., 13:])


def test_rolling_shutter_rows_match_overlap_formula():
    f, duty, exposure, row_time = torch.tensor([30.0]), torch.tensor([0.1]), torch.tensor([0.002]), 5e-5
    # whole stripes only ("interior" frames, one stripe per frame): (on time + exposure) / row time
    rows = physics.rolling_shutter_rows_lit(f, duty, exposure, row_time, image_rows=480, frames="interior")
    assert float(rows) == pytest.approx((0.1 / 30 + 0.002) / 5e-5)
    offset = physics.rolling_shutter_rows_lit(
        f, duty, exposure, row_time, image_rows=480, integration_offset_s=5e-4, frames="interior"
    )
    assert float(offset - rows) == pytest.approx(10.0)
    # every frame averaged: the lit share of a random phase, whatever the row time
    every = physics.rolling_shutter_rows_lit(f, duty, exposure, row_time, image_rows=720, frames="all")
    assert float(every) == pytest.approx(720 * (0.1 / 30 + 0.002) * 30)
    many = physics.rolling_shutter_rows_lit(
        torch.tensor([1000.0]), torch.tensor([0.5]), exposure, row_time, image_rows=720
    )
    assert float(many) == pytest.approx(720.0)  # the window always holds part of a pulse: the frame is lit


def test_rolling_shutter_row_light_counts_stripes():
    light = physics.rolling_shutter_row_light(720, 750.0, 0.2, 3.2e-5, 4e-5, dtype=torch.float64)
    lit = (light[0] > 0.5).to(torch.int8)
    stripes = int((lit[1:] - lit[:-1] == 1).sum()) + int(lit[0])
    period_rows = 1 / (750.0 * 4e-5)
    assert abs(stripes - 720 / period_rows) <= 1.5


def test_blur_paths_and_line_blur():
    uniform = physics.blur_path_offsets("uniform", 1000, dtype=torch.float64)
    sinus = physics.blur_path_offsets("sinusoidal", 1000, dtype=torch.float64)
    # arcsine density: more samples near the ends than a uniform path
    assert (sinus.abs() > 0.4).float().mean() > 2 * (uniform.abs() > 0.4).float().mean()
    with pytest.raises(ValueError, match="uniform, sinusoidal"):
        physics.blur_path_offsets("zigzag", 5)
    x = torch.rand(2, 3, 16, 16, generator=torch.Generator().manual_seed(1))
    assert torch.allclose(physics.line_blur(x, 0.0, 0.0, uniform.float()), x, atol=1e-5)
    flat = torch.full((1, 3, 8, 8), 0.3)
    assert torch.allclose(physics.line_blur(flat, 5.0, 2.0, sinus.float()[::50]), flat, atol=1e-6)


def reference_line_blur(x, dx, dy, offsets):
    """The per-tap form ``line_blur`` computes: each tap shifts the pixel grid's two coordinates and samples."""
    batch, _, height, width = x.shape
    grid_y, grid_x = torch.meshgrid(
        torch.linspace(-1.0, 1.0, height, dtype=x.dtype),
        torch.linspace(-1.0, 1.0, width, dtype=x.dtype),
        indexing="ij",
    )
    dx, dy = (torch.as_tensor(v, dtype=x.dtype).reshape(-1).expand(batch) for v in (dx, dy))
    total = torch.zeros_like(x)
    for offset in offsets.to(x.dtype):
        gx = grid_x + (offset * dx * (2.0 / (width - 1))).reshape(-1, 1, 1)
        gy = grid_y + (offset * dy * (2.0 / (height - 1))).reshape(-1, 1, 1)
        grid = torch.stack([gx, gy], dim=-1)
        total = total + torch.nn.functional.grid_sample(x, grid, padding_mode="border", align_corners=True)
    return total / len(offsets)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_line_blur_is_the_per_tap_sampling(dtype):
    """The sparse whole-pixel kernel sums what the per-tap bilinear sampling sums, to rounding: per-sample and
    shared shifts, both paths, either sign, paths longer than the image (the border replicated)."""
    generator = torch.Generator().manual_seed(3)
    tolerance = {torch.float32: 2e-6, torch.float64: 1e-12}[dtype]
    for height, width, reach in [(21, 34, 5.0), (9, 7, 12.0), (2, 40, 3.0)]:
        x = torch.rand(3, 3, height, width, generator=generator, dtype=dtype)
        dx = torch.randn(3, generator=generator, dtype=dtype) * reach
        dy = torch.randn(3, generator=generator, dtype=dtype) * reach / 3
        for path in physics.BLUR_PATHS:
            offsets = physics.attack_blur_offsets(
                path, physics.blur_taps(float(dx.abs().max()), float(dy.abs().max()))
            )
            offsets = offsets.to(dtype)
            for shift_x, shift_y in [(dx, dy), (float(dx[0]), float(dy[0])), (dx[[0, 1, 0]], dy[[0, 1, 0]])]:
                torch.testing.assert_close(
                    physics.line_blur(x, shift_x, shift_y, offsets),
                    reference_line_blur(x, shift_x, shift_y, offsets),
                    atol=tolerance,
                    rtol=0.0,
                )


def test_line_blur_differentiates_the_image_not_the_shifts():
    offsets = physics.attack_blur_offsets("uniform", 7, dtype=torch.float64)
    image = torch.rand(2, 3, 8, 9, generator=torch.Generator().manual_seed(4), dtype=torch.float64)
    weights = torch.rand(2, 3, 8, 9, generator=torch.Generator().manual_seed(5), dtype=torch.float64)
    gradients = []
    for blur in (physics.line_blur, reference_line_blur):
        x = image.clone().requires_grad_(True)
        (blur(x, torch.tensor([3.5, -2.0]), torch.tensor([1.0, 0.5]), offsets) * weights).sum().backward()
        gradients.append(x.grad)
    torch.testing.assert_close(*gradients, atol=1e-12, rtol=0.0)
    shift = torch.tensor(2.0, requires_grad=True)
    with pytest.raises(ValueError, match="not differentiable in dx, dy"):
        physics.line_blur(image, shift, 0.0, offsets)


def test_em_colour_map_and_masks():
    x = torch.tensor([0.2, 0.3, 0.4]).reshape(1, 3, 1, 1)
    y = physics.em_color_map(x, 2.0, 0.1)
    assert torch.allclose(y.flatten(), torch.tensor([0.6, 0.2, 0.6]), atol=1e-6)
    flip = physics.bayer_flip_mask(10, torch.tensor([4.0]))
    assert flip.flatten().tolist() == [0.0] * 4 + [1.0] * 6
    bands = physics.periodic_band_mask(8, 4.0)
    assert bands.flatten().tolist() == [1, 1, 0, 0, 1, 1, 0, 0]


# OpenCV names a Bayer pattern by the second row's two first sites (its BG is the RGGB tile)
OPENCV_BAYER = {
    "RGGB": "COLOR_BayerBG2RGB",
    "GRBG": "COLOR_BayerGB2RGB",
    "GBRG": "COLOR_BayerGR2RGB",
    "BGGR": "COLOR_BayerRG2RGB",
}


def all_lines_moved(frame: torch.Tensor, pattern: str) -> torch.Tensor:
    """The demosaic when a line above the frame was lost: every raw line moved up by one."""
    terms, weights = physics.bayer_line_terms(frame, pattern)
    return physics.demosaic_of_moved_lines(terms, weights, torch.ones(frame.shape[0], frame.shape[-2]))


@pytest.mark.parametrize("pattern", list(physics.BAYER_PATTERNS))
def test_demosaic_after_a_lost_line_is_opencvs_bilinear_demosaic_of_the_raw_lines_moved_up(pattern):
    """Mosaic the frame with the tile, move the raw lines up by one, demosaic: OpenCV's bilinear demosaic of the
    same mosaic (16-bit) agrees inside the frame's one-pixel border (OpenCV's border rule differs)."""
    cv2 = pytest.importorskip("cv2")
    rng = np.random.default_rng(4)
    frame = rng.uniform(size=(3, 12, 14))
    tile = np.array(physics.BAYER_PATTERNS[pattern])
    sites = tile[np.arange(12)[:, None] % 2, np.arange(14)[None, :] % 2]
    raw = np.take_along_axis(frame, sites[None], 0)[0]
    moved_up = np.concatenate([raw[1:], raw[-1:]])
    expected = cv2.cvtColor(np.round(moved_up * 65535).astype(np.uint16), getattr(cv2, OPENCV_BAYER[pattern]))
    expected = expected.astype(np.float64).transpose(2, 0, 1) / 65535
    got = all_lines_moved(torch.from_numpy(frame).unsqueeze(0), pattern)[0].numpy()
    assert np.abs(got - expected)[:, 1:-2, 1:-1].max() < 1e-4
    # red sites now hold the green sample of the site below, which they keep
    red_sites = sites == 0
    assert np.allclose(got[0][:-1][red_sites[:-1]], frame[1][1:][red_sites[:-1]])


@pytest.mark.parametrize("pattern", list(physics.BAYER_PATTERNS))
def test_the_demosaic_colour_map_of_one_colour_is_the_papers_map_with_a_green_zipper(pattern):
    colour = torch.tensor([0.2, 0.3, 0.5], dtype=torch.float64).reshape(1, 3, 1, 1)
    frame = colour.expand(1, 3, 6, 8)
    mapped = physics.em_colours_of_demosaic(all_lines_moved(frame, pattern), 2.0, 0.1)[
        ..., :-2, :
    ]  # above the last raw line
    paper = physics.em_color_map(colour, 2.0, 0.1)
    assert torch.allclose(mapped[:, [0, 2]], paper[:, [0, 2]].expand_as(mapped[:, [0, 2]]))
    green = mapped[0, 1]
    assert set(np.round(green.unique().numpy(), 9)) == {0.1, 0.25, 0.4}  # blue or red kept, or their mean
    assert torch.allclose(green.reshape(2, 2, 4, 2).mean((1, 3)), paper[0, 1, 0, 0].expand(2, 4))
    with pytest.raises(ValueError, match="valid: RGGB, GRBG, GBRG, BGGR"):
        physics.bayer_line_terms(frame, "RGBG")


@pytest.mark.parametrize("pattern", ["RGGB", "GBRG"])
def test_lost_lines_in_bands_demosaic_the_moved_mosaic_rows_beside_the_bands_included(pattern):
    """Rows whose raw line moved up show the map's colours on OpenCV's demosaic of the mosaic with those lines
    moved; the other rows keep their colours plus that demosaic's change, which reaches the row on each side of a
    band (inside the one-pixel border)."""
    cv2 = pytest.importorskip("cv2")
    rng = np.random.default_rng(6)
    frame = rng.uniform(size=(3, 16, 14))
    moved = np.zeros(16, bool)
    moved[4:8] = moved[11:13] = True
    tile = np.array(physics.BAYER_PATTERNS[pattern])
    sites = tile[np.arange(16)[:, None] % 2, np.arange(14)[None, :] % 2]
    raw = np.take_along_axis(frame, sites[None], 0)[0]
    raw_moved = np.where(moved[:, None], np.concatenate([raw[1:], raw[-1:]]), raw)

    def opencv(mosaic):
        rgb = cv2.cvtColor(np.round(mosaic * 65535).astype(np.uint16), getattr(cv2, OPENCV_BAYER[pattern]))
        return torch.from_numpy(rgb.astype(np.float64).transpose(2, 0, 1) / 65535).unsqueeze(0)

    after, before = opencv(raw_moved), opencv(raw)
    x = torch.from_numpy(frame).unsqueeze(0)
    expected = torch.where(
        torch.from_numpy(moved).reshape(1, 1, 16, 1),
        physics.em_colours_of_demosaic(after, 1.2, 0.03),
        (x + after - before).clamp(0, 1),
    )
    terms, weights = physics.bayer_line_terms(x, pattern)
    got = physics.em_demosaic_rows(terms, weights, x, torch.from_numpy(moved)[None], 1.2, 0.03)
    assert (got - expected).abs()[..., 1:-2, 1:-1].max() < 1e-4
    beside = [3, 8, 10, 13]  # rows next to a band, not in it
    assert (got - x)[0, :, beside, 1:-1].abs().amax(dim=(0, 2)).min() > 1e-3


def test_a_recording_that_does_not_drift_is_the_interior_rule_and_a_whole_period_is_the_lit_rule():
    """Phase drift bridges the two frame rules: a locked phase (drift 0) sees the whole stripes the interior rule
    counts, exactly; a phase that covers the whole period (drift 1) any phase, as the lit rule does (to the
    grid's resolution). One stripe per frame (25 Hz) and several (750 Hz)."""
    f = torch.tensor([25.0, 25.0, 25.0, 750.0, 300.0])
    duty = torch.tensor([0.3, 0.1, 0.01, 0.2, 0.05])
    exposure = torch.tensor([5e-5, 1e-3, 5e-5, 3.2e-5, 2e-3])
    kwargs = {"image_rows": 720, "integration_offset_s": 3e-4}
    interior = physics.rolling_shutter_rows_lit(f, duty, exposure, 2e-5, frames="interior", **kwargs)
    lit = physics.rolling_shutter_rows_lit(f, duty, exposure, 2e-5, frames="lit", **kwargs)
    locked = physics.rolling_shutter_rows_lit(
        f, duty, exposure, 2e-5, frames="interior", drift=torch.zeros(5), **kwargs
    )
    covering = physics.rolling_shutter_rows_lit(
        f, duty, exposure, 2e-5, frames="interior", drift=torch.ones(5), **kwargs
    )
    torch.testing.assert_close(locked, interior, rtol=1e-9, atol=1e-9)
    torch.testing.assert_close(covering, lit, rtol=0.02, atol=0.5)
    assert float((interior - lit).abs().max()) > 100  # the two rules differ here, so both checks could fail


def test_drift_cuts_wide_stripes_first():
    """A drifting phase cuts a stripe at the frame's edges in part of the frames: the count falls as the drift
    grows, and a stripe filling most of the frame loses a larger share than a narrow one."""
    drift = torch.tensor([0.0, 0.05, 0.2, 0.5])
    kwargs = {"image_rows": 720, "frames": "interior", "drift": drift}
    wide = physics.rolling_shutter_rows_lit(
        torch.full((4,), 25.0), torch.full((4,), 0.3), 5e-5, 2e-5, **kwargs
    )
    narrow = physics.rolling_shutter_rows_lit(
        torch.full((4,), 25.0), torch.full((4,), 0.02), 5e-5, 2e-5, **kwargs
    )
    assert (wide[1:] < wide[:-1]).all() and (narrow[1:] <= narrow[:-1]).all(), (wide, narrow)
    assert float(wide[-1] / wide[0]) < float(narrow[-1] / narrow[0]) - 0.1, (wide, narrow)


def test_a_recording_that_starts_as_its_stripes_come_into_view_is_cut_only_after_crossing_the_frame():
    """``drift_start="entry"``: a locked recording counts what the interior rule counts; a drifting one keeps its
    stripe whole until the stripe has crossed the frame's free span (the frame minus the stripe), then loses it row
    by row at the far edge: for one stripe per frame the mean over lit frames has a closed form, checked against
    the kernel; a drift that does not reach the far edge cuts nothing, where a start at any placement cuts."""
    f = torch.tensor([25.0, 25.0, 750.0, 300.0])
    duty = torch.tensor([0.3, 0.1, 0.2, 0.05])
    exposure = torch.tensor([5e-5, 1e-3, 3.2e-5, 2e-3])
    kwargs = {"image_rows": 720, "integration_offset_s": 3e-4, "frames": "interior"}
    interior = physics.rolling_shutter_rows_lit(f, duty, exposure, 2e-5, **kwargs)
    locked = physics.rolling_shutter_rows_lit(
        f, duty, exposure, 2e-5, drift=torch.zeros(4), drift_start="entry", **kwargs
    )
    torch.testing.assert_close(locked, interior, rtol=1e-9, atol=1e-9)

    row_time, height = 2e-5, 720
    period_rows = 1.0 / (25.0 * row_time)  # 2000 rows: one stripe per frame
    width = (0.25 / 25.0 + 5e-5 + 3e-4) / row_time  # 517.5 rows
    free = (height - 1) - width
    drifts = torch.tensor([0.5 * free, 0.9 * free, free + 0.5 * width, free + width], dtype=torch.float64)
    drifts = drifts / period_rows
    n = len(drifts)
    drifting = functools.partial(
        physics.rolling_shutter_rows_lit,
        torch.full((n,), 25.0),
        torch.full((n,), 0.25),
        torch.full((n,), 5e-5),
        row_time,
        image_rows=height,
        integration_offset_s=3e-4,
        frames="interior",
        drift=drifts,
    )
    cut = drifting(drift_start="entry")
    travel = drifts * period_rows
    beyond = (travel - free).clamp(min=0.0)
    expected = (travel.clamp(max=free) * width + beyond * (width - beyond / 2)) / travel
    torch.testing.assert_close(cut, expected, rtol=0.01, atol=1.0)
    assert float(cut[1]) == pytest.approx(width, abs=1e-6) and float(cut[-1]) < 0.8 * width, cut
    anywhere = drifting(drift_start="placement")
    assert float(anywhere[1]) < width - 20.0, anywhere
    # a laser period shorter than the frame (the Logitech table: 30.1 Hz, 48.9 us rows, 679 rows a period): the run
    # of whole frames ends where a neighbouring stripe reaches an edge row, and a small drift from its start still
    # cuts nothing (it once moved every count a row, the start sitting on that edge)
    several = {
        "image_rows": 720,
        "integration_offset_s": 3.5e-4,
        "frames": "interior",
        "drift_start": "entry",
    }
    counts = [
        physics.rolling_shutter_rows_lit(
            torch.full((3,), 30.1),
            torch.tensor([0.05, 0.15, 0.3]),
            1.5e-3,
            4.89e-5,
            drift=torch.full((3,), d),
            **several,
        )
        for d in (0.0, 0.02, 0.1)
    ]
    torch.testing.assert_close(counts[1], counts[0], rtol=0.0, atol=1e-6)
    torch.testing.assert_close(counts[2], counts[0], rtol=0.0, atol=1e-6)
    for drift in (torch.zeros(4), None):  # a bad start is an error whether or not a drift is given
        with pytest.raises(ValueError, match="placement, entry"):
            physics.rolling_shutter_rows_lit(f, duty, exposure, 2e-5, drift=drift, drift_start="x", **kwargs)


def test_a_recording_of_n_frames_averages_its_own_frames():
    """``recording_frames=N`` takes a drifting recording at its N frames (frame k advanced by k drift / N): one
    frame is the locked interior count; from the entry, one stripe per frame, the mean over lit frames is a sum over
    the N frames in closed form; a long recording reaches the arc's midpoint limit (``None``); rows of different
    lengths in one batch each count only their own frames; a count that is not a whole number >= 1 is refused."""
    row_time, height = 2e-5, 720
    kwargs = {"image_rows": height, "integration_offset_s": 3e-4, "frames": "interior"}
    f, duty, exposure = torch.tensor([25.0, 25.0, 300.0]), torch.tensor([0.3, 0.1, 0.05]), 5e-5
    interior = physics.rolling_shutter_rows_lit(f, duty, exposure, row_time, **kwargs)
    one_frame = physics.rolling_shutter_rows_lit(
        f, duty, exposure, row_time, drift=torch.full((3,), 0.4), recording_frames=1, **kwargs
    )
    torch.testing.assert_close(one_frame, interior, rtol=1e-9, atol=1e-9)

    period_rows = 1.0 / (25.0 * row_time)  # 2000 rows: one stripe per frame
    width = (0.25 / 25.0 + exposure + 3e-4) / row_time  # 517.5 rows
    free = (height - 1) - width
    travel = 1.6 * free  # the stripe crosses the free span, then leaves the frame in part of the frames
    frames = torch.tensor([6, 24, 96])
    drifting = functools.partial(
        physics.rolling_shutter_rows_lit,
        torch.full((3,), 25.0),
        torch.full((3,), 0.25),
        exposure,
        row_time,
        drift=torch.full((3,), travel / period_rows),
        drift_start="entry",
        **kwargs,
    )
    counts = drifting(recording_frames=frames)
    for n, count in zip(frames.tolist(), counts, strict=True):
        moved = travel * np.arange(n) / n
        rows = width - np.clip(moved - free, 0.0, None)
        torch.testing.assert_close(float(count), float(rows[rows > 0].mean()), rtol=0.01, atol=1.0)
    torch.testing.assert_close(counts[1:2], drifting(recording_frames=24)[1:2], rtol=1e-12, atol=1e-9)
    long = drifting(recording_frames=4096)
    torch.testing.assert_close(long, drifting(), rtol=2e-3, atol=0.0)
    assert float(counts[0] - long[0]) > 5.0, (
        counts,
        long,
    )  # six frames differ from the limit: the check bites
    for bad in (0, 2.5, torch.tensor([24.0, float("nan"), 24.0])):
        with pytest.raises(ValueError, match="whole numbers >= 1"):
            drifting(recording_frames=bad)


def test_without_a_threshold_a_row_is_lit_for_the_pulse_plus_its_window_and_no_longer():
    """Threshold 0: the start times that collect any pulse span on + window, capped at the period, whatever the
    rounding of the light on the dark pieces (once 6.9e-18 s, not 0, at 24.3 Hz, 2% duty and a 281 us window: the
    whole period counted as lit); drawn over frequencies, duties and windows of several cameras, in float64."""
    generator = torch.Generator().manual_seed(20261129)
    n = 20000
    frequency = 10.0 ** (1.0 + 3.0 * torch.rand(n, generator=generator, dtype=torch.float64))
    frequency = torch.round(frequency * 10.0) / 10.0  # as tables write them: 24.3 Hz
    duty = torch.randint(1, 100, (n,), generator=generator).to(torch.float64) / 100.0
    window = torch.round(10.0 ** (1.0 + 2.6 * torch.rand(n, generator=generator, dtype=torch.float64))) * 1e-6
    frequency, duty, window = (
        torch.cat([torch.tensor([24.3], dtype=torch.float64), v]) for v in (frequency, duty, window)
    )
    duty[0], window[0] = 0.02, 281e-6
    period = 1.0 / frequency
    on = duty * period
    reached = physics.pulse_overlap_lit_time(period, on, window)
    expected = torch.minimum(on + window, period)
    torch.testing.assert_close(reached, expected, rtol=1e-9, atol=0.0)


def test_a_closing_set_of_whole_stripe_placements_keeps_its_count():
    """One stripe of ~232 rows in a 419-row period on a 600-row frame (drawn camera 1222484455, 59.9 Hz at 50%):
    whole-stripe frames exist only while the row time is below ~39.9 us, and a measured row says they occurred. As
    the row time grows past that point the interior count stays with the stripe's width (the open side's limit,
    then the frames nearest to whole) instead of jumping to the lit rule's ~335 rows."""
    row_times = torch.linspace(39.5e-6, 40.5e-6, 201, dtype=torch.float64)
    kwargs = {
        "image_rows": 600,
        "integration_offset_s": 3.16e-5,
        "threshold_s": 1.17e-5,
        "frames": "interior",
    }
    interior = physics.rolling_shutter_rows_lit(
        torch.tensor(59.9), torch.tensor(0.5), torch.tensor(879e-6), row_times, **kwargs
    )
    lit = physics.rolling_shutter_rows_lit(
        torch.tensor(59.9), torch.tensor(0.5), torch.tensor(879e-6), row_times, **(kwargs | {"frames": "lit"})
    )
    period = 1.0 / 59.9 / row_times
    width = (0.5 / 59.9 + 879e-6 + 3.16e-5 - 2 * 1.17e-5) / row_times
    closed, _ = physics._nearest_closed_placement(period, width, torch.tensor(599.0))
    assert closed.any() and (~closed).any()  # the grid crosses the closing point
    assert float((lit - interior).min()) > 80  # where the lit rule stood before
    assert float(interior.diff().abs().max()) < 1.0
    torch.testing.assert_close(interior[~closed], width[~closed], rtol=1e-6, atol=0.0)
    assert float((interior[closed] - width[closed]).abs().max()) < 20.0
    # a drifting recording of a closed set starts at the placement that stands for it: continuous too
    for drift in (0.0, 0.05):
        drifting = physics.rolling_shutter_rows_lit(
            torch.tensor(59.9),
            torch.tensor(0.5),
            torch.tensor(879e-6),
            row_times,
            drift=torch.tensor(drift),
            **kwargs,
        )
        assert float(drifting.diff().abs().max()) < 1.0, drift
        assert float((lit - drifting).min()) > 80, drift


def test_a_shoulder_curve_inverts_keeps_white_and_rolls_off_its_highlights():
    light = torch.linspace(1e-4, 1.0, 400, dtype=torch.float64)
    curve = physics.ShoulderCurve(20.0, 1.3, 1.1)
    assert torch.allclose(physics.decode(physics.encode(light, curve), curve), light, rtol=1e-9, atol=1e-12)
    assert float(curve.encode(torch.tensor(1.0, dtype=torch.float64))) == pytest.approx(1.0)
    # no shoulder: the display power law itself
    assert torch.allclose(physics.ShoulderCurve(0.0, 2.7, 2.2).encode(light), physics.encode(light, 2.2))
    # at white the curve climbs 1 / (gamma (1 + s)) per unit of light, the power law 1 / gamma: highlights that
    # would clip roll off (d/dx of ((1 + s) x^n / (1 + s x^n)) ** (1 / (n gamma)) at x = 1)
    step = torch.tensor([1.0 - 1e-6, 1.0], dtype=torch.float64)
    slope = float(curve.encode(step).diff()) / 1e-6
    assert slope == pytest.approx(1.0 / (1.1 * 21.0), rel=1e-3)


@pytest.mark.parametrize(
    ("options", "valid"),
    [
        ({"shoulder": -1.0}, "shoulder >= 0"),
        ({"shoulder": 2.0, "shoulder_exponent": 0.0}, "exponent > 0"),
        ({"shoulder": 2.0, "gamma": 0.0}, "display gamma > 0"),
    ],
)
def test_a_shoulder_out_of_its_range_is_refused_with_the_valid_values(options, valid):
    with pytest.raises(ValueError, match=valid):
        physics.tone_options(
            options.get("gamma", 2.2),
            options["shoulder"],
            options.get("shoulder_exponent", 1.0),
            owner="attack",
        )


def test_a_shoulder_exponent_without_a_shoulder_is_refused():
    with pytest.raises(ValueError, match="needs shoulder="):
        physics.tone_options(2.2, None, 2.0, owner="attack")
    assert physics.tone_options(2.2, None, 1.0, owner="attack") == 2.2
    assert physics.tone_options(None, 3.0, 0.5, owner="attack") == physics.ShoulderCurve(3.0, 0.5, 1.0)


def test_a_frame_meters_alike_alone_and_beside_frames_that_need_more_steps():
    """Each frame's Newton steps stop at its own last step: a faint light (one linear piece, settled at once) metered
    beside a clipping laser (several steps) keeps the bits it has alone. Stopped together (until session 96), it took
    the laser frame's steps and moved by rounding (2.2e-16 on this draw), and a calibration's fit moved when only
    held-out frames changed."""
    g = torch.Generator().manual_seed(3)
    for _ in range(2):  # the second draw is the one whose rounding moved
        scene = torch.rand(2, 256, generator=g, dtype=torch.float64) * 0.6
        total = scene.clone()
        total[1, :40] += torch.rand(40, generator=g, dtype=torch.float64) * 30
        total[0] += 0.05 * torch.rand(256, generator=g, dtype=torch.float64)
    alone = physics.metered_exposure(total[:1], scene[:1])
    beside = physics.metered_exposure(total, scene)
    assert torch.equal(alone[0], beside[0])
    assert beside[1] < 0.9 * beside[0]  # the laser frame is exposed down, over more steps
