"""Reading a capture of the laser alone (``transforms/capture.py``), as the physical laser blinding and the
calibration read it.

A capture of the laser alone holds the beam plus the capture's own dark noise. Scaled by the power ratio between
the blinded frames and the capture, the noise must not be scaled with it, and the beam's light below the capture's
noise floor must not be lost (at tens of times the capture's power it lights the frame far around the spot). The
image operations are torch's own, held to scipy's (the calibration's until session 89) to rounding.
"""

from __future__ import annotations

import io

import numpy as np
import pytest
import torch
from PIL import Image

from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.base import REFERENCE_SIZE
from lerobot_phantom.transforms.capture import (
    beam_profile,
    core_continued,
    dark_field,
    dark_level,
    dark_surface,
    pattern_centre,
    read_capture,
    room_gradient,
)

HEIGHT, WIDTH = 48, 64
CENTRE = (30.0, 22.0)  # (x, y)
DARK = 0.006  # linear light of the dark room
BLOOM_SIGMA = 8.0


def beam(radius: np.ndarray) -> np.ndarray:
    """Linear light of a beam with a Gaussian core and a wider Gaussian bloom, 0.7 of the full well at its peak."""
    return 0.7 * (np.exp(-(radius**2) / (2 * 3.0**2)) + 0.15 * np.exp(-(radius**2) / (2 * BLOOM_SIGMA**2)))


def capture(rng: np.random.Generator, noise: float) -> tuple[torch.Tensor, np.ndarray]:
    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH].astype(float)
    radius = np.hypot(xs - CENTRE[0], ys - CENTRE[1])
    light = beam(radius)[None] * np.array([0.1, 1.0, 0.2])[:, None, None] + DARK
    noisy = np.clip(light + rng.normal(0.0, noise, light.shape), 0.0, 1.0)
    encoded = np.round(physics.linear_to_srgb(torch.from_numpy(noisy)).numpy() * 255) / 255
    return torch.from_numpy(encoded), radius


def read_beam(pattern: torch.Tensor) -> np.ndarray:
    """Green channel of the read beam profile, linear light above the dark level."""
    centre = pattern_centre(pattern)
    dark = dark_level(pattern, centre)
    profile = beam_profile(pattern, dark, centre).profile
    return (physics.srgb_to_linear(profile) - physics.srgb_to_linear(dark).reshape(3, 1, 1))[1].numpy()


def test_capture_noise_is_not_read_as_laser_light():
    pattern, radius = capture(np.random.default_rng(3), noise=6e-4)
    far = radius > 35  # the beam is below 1e-5 of the full well there: what the capture holds is noise
    raw = physics.srgb_to_linear(pattern)[1].numpy() - physics.srgb_to_linear(pattern)[1].numpy()[far].mean()
    read = read_beam(pattern)
    # scaled by a power ratio of 50, the raw capture's noise would be 50 x its spread in the blinded frame
    assert read[far].std() < 0.2 * raw[far].std()
    assert np.abs(read[far]).max() < 3 * 6e-4


def test_beam_is_continued_below_the_noise_floor():
    pattern, radius = capture(np.random.default_rng(4), noise=6e-4)
    read = read_beam(pattern)
    true = beam(radius)
    # where the beam has sunk to 0.5-1.5 times the capture's noise it cannot be read pixel by pixel; the read
    # profile continues the measured fall-off: within a factor 2 of the truth on average, where a clamp at the
    # dark level would hold 0 (or the noise's positive half)
    below = (true > 0.5 * 6e-4) & (true < 1.5 * 6e-4)
    assert below.sum() > 20
    ratio = read[below].mean() / true[below].mean()
    assert 0.5 < ratio < 2.0, ratio
    # and the measured beam itself is kept where it stands well above the noise
    bright = true > 0.05
    assert np.allclose(read[bright], true[bright], rtol=0.15)


def test_a_channel_without_a_measurable_edge_is_named_not_skipped_silently(caplog):
    pattern, _ = capture(np.random.default_rng(5), noise=6e-4)
    # the blue channel holds only the dark room: no beam, so no edge to continue below the floor
    pattern[2] = physics.linear_to_srgb(torch.full_like(pattern[2], DARK))
    centre = pattern_centre(pattern)
    with caplog.at_level("WARNING", logger="lerobot_phantom.calibration.frame_models.laser_blinding"):
        profile = beam_profile(pattern, dark_level(pattern, centre), centre).profile
    warned = [record.getMessage() for record in caplog.records]
    assert any("channel 2" in message for message in warned), warned
    assert not any("channel 1" in message for message in warned), warned
    # the dark channel reads as no laser light at all
    assert torch.allclose(profile[2], pattern[2], atol=1e-6)


def jpeg(pattern: torch.Tensor, quality: int = 90) -> torch.Tensor:
    """The capture stored as a camera stores it: JPEG, its colour subsampled (4:2:0)."""
    buffer = io.BytesIO()
    Image.fromarray((pattern.permute(1, 2, 0).numpy() * 255).round().astype(np.uint8)).save(
        buffer, format="JPEG", quality=quality
    )
    decoded = np.asarray(Image.open(io.BytesIO(buffer.getvalue())), dtype=np.float64) / 255
    return torch.from_numpy(decoded).permute(2, 0, 1).contiguous()


def test_every_channel_carries_the_laser_colour():
    # a red laser with a glare tail: the green and blue channels hold 0.1 and 0.04 of its light everywhere, and
    # sink below their noise floors far nearer the spot than red does
    colour = np.array([1.0, 0.1, 0.04])
    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH].astype(float)
    radius = np.hypot(xs - CENTRE[0], ys - CENTRE[1])
    true = beam(radius) + 0.01 / (1 + radius**2 / 4.0**2)
    light = true[None] * colour[:, None, None] + DARK
    noisy = np.clip(light + np.random.default_rng(4).normal(0.0, 6e-4, light.shape), 0.0, 1.0)
    pattern = jpeg(physics.linear_to_srgb(torch.from_numpy(noisy)))
    centre = pattern_centre(pattern)
    dark = dark_level(pattern, centre)
    read = (
        physics.srgb_to_linear(beam_profile(pattern, dark, centre).profile)
        - physics.srgb_to_linear(dark).reshape(3, 1, 1)
    ).numpy()
    # where only red is measured (0.5-3 noise deviations of light in it, the others far below their floors), the
    # continued green and blue hold the laser's colour, not their own faint edges' fall-off
    far = (true > 0.5 * 6e-4) & (true < 3 * 6e-4)
    assert far.sum() > 100
    for c in (1, 2):
        ratio = read[c][far].mean() / read[0][far].mean()
        assert ratio == pytest.approx(colour[c], rel=0.2), (c, ratio)
    # nearer the spot, where compression bleeds red's steep edge into the faint channels, they still follow it
    for low, high in [(3, 6), (6, 10), (10, 15), (15, 20), (20, 30)]:
        ring = (radius >= low) & (radius < high)
        for c in (1, 2):
            assert read[c][ring].mean() / (colour[c] * true[ring].mean()) == pytest.approx(1.0, abs=0.25), (
                c,
                low,
            )


def test_the_image_operations_are_scipys_to_rounding():
    """Gaussian filter (borders replicated), median absolute deviation, line fit, hole filling and distance
    transform against scipy's and numpy's, on random images, sample sizes of both parities and blobs with holes."""
    from scipy import ndimage, stats

    from lerobot_phantom.transforms import capture as read

    generator = torch.Generator().manual_seed(11)
    for trial in range(12):
        height, width = (int(v) for v in torch.randint(6, 50, (2,), generator=generator))
        image = torch.rand(3, height, width, generator=generator, dtype=torch.float64)
        scipy_smooth = ndimage.gaussian_filter(image.numpy(), sigma=(0, 1.0, 1.0), mode="nearest")
        torch.testing.assert_close(
            physics.gaussian_spread(image[None], 1.0, radius=4)[0],
            torch.from_numpy(scipy_smooth),
            atol=1e-14,
            rtol=0,
        )
        values = torch.randn(3, 20 + trial, generator=generator, dtype=torch.float64)
        spread = stats.median_abs_deviation(values.numpy(), axis=1, scale="normal")
        torch.testing.assert_close(read.robust_spread(values), torch.from_numpy(spread), atol=1e-14, rtol=0)
        x = torch.rand(40, generator=generator, dtype=torch.float64) * 100
        y = -0.03 * x + torch.randn(40, generator=generator, dtype=torch.float64)
        assert read.line_fit(x, y) == pytest.approx(tuple(np.polyfit(x.numpy(), y.numpy(), 1)), rel=1e-10)
        ys, xs = torch.meshgrid(torch.arange(height), torch.arange(width), indexing="ij")
        disc = (ys - height / 2) ** 2 + (xs - width / 3) ** 2 < (min(height, width) / 3) ** 2
        blob = (disc & (torch.rand(height, width, generator=generator) > 0.1)) | (
            torch.rand(height, width, generator=generator) > 0.97
        )
        filled = read.fill_holes(blob)
        assert torch.equal(filled, torch.from_numpy(ndimage.binary_fill_holes(blob.numpy())))
        distances = torch.from_numpy(ndimage.distance_transform_edt(filled.numpy()))
        torch.testing.assert_close(read.distance_to_background(filled), distances, atol=1e-12, rtol=0)
    with pytest.raises(ValueError, match="whole frame"):
        read.distance_to_background(torch.ones(4, 4, dtype=torch.bool))
    row = torch.tensor([[False, True, True, True, False, True]])  # one row, and blocks of one pair
    torch.testing.assert_close(
        read.distance_to_background(row, pairs=1),
        torch.from_numpy(ndimage.distance_transform_edt(row.numpy())),
    )


def test_a_dark_frame_of_another_size_is_refused():
    """A dark frame repeats its capture pixel for pixel: one of another size (a pairs.csv row pointing at another
    camera's frame) is refused with both shapes named, where its fitted surface would not broadcast onto the capture
    or would silently describe another frame; without a dark frame, a uniform room's field is its one level."""
    capture = torch.full((3, 24, 32), 0.05, dtype=torch.float64)
    capture[:, 10:14, 14:18] = 1.0
    centre = pattern_centre(capture)
    with pytest.raises(ValueError, match=r"its capture's shape \(3, 24, 32\), got \(3, 12, 16\)"):
        dark_field(capture, torch.zeros(3, 12, 16, dtype=torch.float64), centre)
    field = dark_field(capture, None, centre)
    assert field.shape == capture.shape
    torch.testing.assert_close(field, dark_level(capture, centre).expand_as(capture), rtol=0.0, atol=1e-12)


def test_a_saturated_core_is_continued_with_the_beams_narrower_core_inside_its_skirt():
    """A spot whose focused core sits inside a wider skirt, captured saturated out into the skirt (60 full wells at
    the core's peak, the skirt 0.15 of it at 8/3 its width): the saturated edge is the skirt's, and its Gaussian
    continued inwards reaches the skirt's own peak, 9 full wells, where the beam holds 69. With the narrower core
    at its true width and peak over the saturated level (``inner_core_peak``) the continuation follows the beam
    through the core; outside the core nothing changes, and a peak of 0 is the skirt's Gaussian alone."""
    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH].astype(float)
    radius = np.hypot(xs - CENTRE[0], ys - CENTRE[1])
    core_px, skirt_px, peak = 3.0, 8.0, 60.0
    light = peak * (np.exp(-(radius**2) / (2 * core_px**2)) + 0.15 * np.exp(-(radius**2) / (2 * skirt_px**2)))
    stored = np.clip(light[None] * np.array([0.1, 1.0, 0.2])[:, None, None] + DARK, 0.0, 1.0)
    pattern = torch.from_numpy(np.round(physics.linear_to_srgb(torch.from_numpy(stored)).numpy() * 255) / 255)
    reading = read_capture(pattern)
    to_reference = REFERENCE_SIZE / WIDTH
    green = slice(1, 2)
    beam, dark = physics.srgb_to_linear(reading.beam)[green], physics.srgb_to_linear(reading.dark)[green]
    depth, core_radius = reading.core_depth[green], reading.core_radius[green]

    def continued(inner_peak: float) -> np.ndarray:
        light = core_continued(
            beam, dark, depth, core_radius, skirt_px * to_reference, inner_peak, core_px * to_reference
        )
        return light[0].numpy()

    level = float((beam - dark)[depth > 0].mean())
    skirt_alone, with_core = continued(0.0), continued(peak / level)
    centre = radius < 1.0
    assert 0.95 < with_core[centre].mean() / light[centre].mean() < 1.05
    assert skirt_alone[centre].mean() < 0.15 * light[centre].mean()
    # where the core outshines the skirt: within 10% of the beam at the median, where the skirt alone is 3x off
    inner = radius < 2 * core_px
    assert np.median(np.abs(np.log(with_core[inner] / light[inner]))) < 0.1
    assert np.median(np.abs(np.log(skirt_alone[inner] / light[inner]))) > 1.0
    outside = (depth[0] == 0).numpy()
    assert np.array_equal(with_core[outside], skirt_alone[outside])
    # without a peak the width is inert: the edge's Gaussian alone, whatever width the inner beam is given
    assert torch.equal(
        core_continued(beam, dark, depth, core_radius, 20.0),
        core_continued(beam, dark, depth, core_radius, 20.0, 0.0, 3.0),
    )


def room_capture(
    rng: np.random.Generator, centre: tuple[float, float], slope: tuple[float, float]
) -> tuple[torch.Tensor, torch.Tensor]:
    """A capture (sRGB, 8-bit, read noise) of an elliptical beam with a power-law glare, in a dark room whose light
    changes by ``slope`` (x, y) of its level across the frame, and the room's departure from its level at the spot
    (linear light): the gradient :func:`room_gradient` should read."""
    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH].astype(float)
    dx, dy = xs - centre[0], ys - centre[1]
    across = np.hypot(dx / 1.0, dy / 0.6)  # an elliptical beam: even under the reflection about its centre
    glare = 0.004 * (1 + (np.hypot(dx, dy) / 4.0) ** 2) ** -1.0
    beam_light = 0.9 * np.exp(-(across**2) / (2 * 3.0**2)) + glare
    departure = DARK * (slope[0] * dx / (WIDTH - 1) + slope[1] * dy / (HEIGHT - 1))
    light = beam_light[None] * np.array([1.0, 0.3, 0.1])[:, None, None] + DARK + departure[None]
    noisy = np.clip(light + rng.normal(0.0, 2e-4, light.shape), 0.0, 1.0)
    encoded = np.round(physics.linear_to_srgb(torch.from_numpy(noisy)).numpy() * 255) / 255
    return torch.from_numpy(encoded), torch.from_numpy(np.broadcast_to(departure, (3, HEIGHT, WIDTH)).copy())


@pytest.mark.parametrize(
    ("centre", "slope"),
    [((30.3, 22.6), (0.3, 0.0)), ((20.7, 28.2), (-0.2, 0.25)), ((40.5, 18.4), (0.0, 0.0))],
)
def test_a_capture_alone_reads_its_rooms_gradient_not_its_glare(centre, slope):
    """A room brighter on one side is odd under the reflection about the spot, the beam and its glare even: the
    capture's odd part gives the gradient to within half a percent of the room's level, and a uniform room none,
    though the glare covers the frame. An error in the spot's centre (here 0.7 px) is fitted beside the gradient:
    without it, the beam's steep light mirrored off its centre reads as a gradient."""
    pattern, departure = room_capture(np.random.default_rng(11), centre, slope)
    # the centre read off the true one by over half a pixel, as a centroid of a clipped or compressed spot can be
    read = room_gradient(pattern, (centre[0] + 0.6, centre[1] - 0.4))
    # about the read centre, not the true one: the two differ by a level, which the dark level takes
    error = (read - read.mean((1, 2), keepdim=True)) - (departure - departure.mean((1, 2), keepdim=True))
    # 0.29% and 0.18% of the room's level where it changes by 30% and 45%, 0.38% where it is uniform; without the
    # centre's error fitted, 0.83% where it changes by 45% and 1.07% where it is uniform
    assert float(error.abs().max()) < 0.005 * DARK + 0.005 * float(departure.max() - departure.min())


def test_a_spot_at_the_frames_corner_reads_no_gradient():
    """With the spot in a corner few pixels have a mirror in the frame: no gradient is read, and the dark field is
    the capture's one level."""
    pattern, _ = room_capture(np.random.default_rng(12), (1.0, 1.0), (0.3, 0.0))
    centre = pattern_centre(pattern)
    assert room_gradient(pattern, centre) is None
    assert torch.equal(dark_field(pattern, None, centre), dark_level(pattern, centre).expand_as(pattern))


def test_the_same_capture_reads_the_same_gradient_every_time():
    """The room's slope is solved by normal equations summed with torch's reductions: LAPACK's lstsq summed in an
    order that followed the BLAS's threads, and the same capture read eight times gave up to three different last
    bits, which moved a calibration's fit when only held-out captures changed."""
    pattern, _ = room_capture(np.random.default_rng(13), (30.3, 22.6), (0.3, 0.1))
    centre = pattern_centre(pattern)
    first = room_gradient(pattern, centre)
    assert all(torch.equal(first, room_gradient(pattern.clone(), centre)) for _ in range(8))


def test_the_same_dark_frame_reads_the_same_surface_every_time():
    """The dark frame's surface likewise: LAPACK's lstsq read one dark frame to four different surfaces in 40 calls
    on one thread, with other tensors allocated between them (docs/bench/session101/dark_surface_repeats.py), and a
    calibration of camsim's halo case with dark frames fitted its halo exponent anywhere from 2.0483 to 2.0485 from
    run to run."""
    dark = torch.rand(3, HEIGHT, WIDTH, generator=torch.Generator().manual_seed(0), dtype=torch.float64) * 0.1
    first, held = dark_surface(dark), []
    for k in range(40):
        held.append(torch.empty(7 * k + 1, dtype=torch.float64))
        assert torch.equal(first, dark_surface(dark.clone())), k
