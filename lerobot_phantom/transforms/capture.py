"""A capture of the laser alone, read as the light it measured (the physical laser blinding and
``lerobot-phantom-calibrate`` read a capture alike, with these functions).

A capture holds the laser's beam plus what is not the laser's: the dark room's light and the sensor's black level
(:func:`dark_level`), the capture's own noise, and, where the capture itself saturated, a core whose irradiance it
could not record. The calibration scales a capture to the attack's power by a gain of tens for a beam-profile
exposure, so each of these would be scaled with it: the dark level is taken out (varying over the frame as a dark
frame's light does, or, without one, as the room's linear gradient read from the capture does: :func:`dark_field`,
:func:`room_gradient`), the beam is read without the noise and continued below the noise floor
(:func:`beam_profile`), and the saturated core is continued as a Gaussian beam (:func:`saturated_depth`,
:func:`core_continued`). Module docstring of ``calibration/frame_models/laser_blinding.py`` for what each reading
fixed on the independent simulator. Pure torch (the image operations the calibration once took from scipy are
written here: medians, a line fit, hole filling and a distance transform; the Gaussian filter is
``physics.gaussian_spread``).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import NamedTuple

import torch
import torch.nn.functional as F

from lerobot_phantom.transforms.base import REFERENCE_SIZE
from lerobot_phantom.transforms.physics import gaussian_spread, linear_to_srgb, srgb_to_linear

logger = logging.getLogger(__name__)


def capture_colour(capture: torch.Tensor) -> torch.Tensor:
    """(3,) the laser's colour in a capture ``(3, H, W)`` in [0, 1]: its linear light per channel, each pixel
    weighted by its mean light (so the beam outweighs the dark room), over the brightest channel's."""
    light = srgb_to_linear(capture).reshape(3, -1)
    weight = light.mean(0)
    colour = (light * weight).sum(1) / weight.sum().clamp(min=1e-9)
    return colour / colour.max().clamp(min=1e-9)


def pattern_centre(pattern: torch.Tensor) -> tuple[float, float]:
    """(x, y) centroid of the brightest part of a laser pattern."""
    luminance = pattern.mean(0)
    mask = luminance >= luminance.max() - 0.05 * max(float(luminance.max() - luminance.min()), 1e-6)
    ys, xs = torch.nonzero(mask, as_tuple=True)
    return float(xs.double().mean()), float(ys.double().mean())


# the share of a capture's pixels, farthest from the spot, whose median is its dark level: the laser's light falls
# with the distance, and in the outer half it can stand far above the dark room's (the beam's bloom in a capture at the
# attack's power, on the independent simulator: the outer half's median 0.070 of the full well where the dark room
# gives 0.0048 at the spot, the farthest tenth's 0.0075; docs/bench/camsim_session24/dark_level_saturation.txt)
DARK_SHARE = 0.1


def dark_region(pattern: torch.Tensor, centre: tuple[float, float]) -> tuple[torch.Tensor, torch.Tensor]:
    """(flat distances of the capture's pixels from the spot's centre, mask of the ``DARK_SHARE`` farthest)."""
    _, height, width = pattern.shape
    ys, xs = torch.meshgrid(
        torch.arange(height, dtype=torch.float64), torch.arange(width, dtype=torch.float64), indexing="ij"
    )
    radius = torch.hypot(xs - centre[0], ys - centre[1]).reshape(-1)
    return radius, radius >= torch.quantile(radius, 1.0 - DARK_SHARE)


def dark_level(pattern: torch.Tensor, centre: tuple[float, float]) -> torch.Tensor:
    """(3, 1, 1): per-channel median (encoded) of the capture's pixels farthest from the spot (``DARK_SHARE``): the dark
    room's light and the black level (a median commutes with any monotone tone curve, so it decodes exactly)."""
    _, far = dark_region(pattern, centre)
    return far_median(pattern, far)


def far_median(values: torch.Tensor, far: torch.Tensor) -> torch.Tensor:
    """(3, 1, 1): each channel's median over the ``far`` pixels of (3, H, W) ``values``."""
    return values.reshape(3, -1)[:, far].median(dim=1).values.reshape(3, 1, 1)


def dark_level_radius(pattern: torch.Tensor, centre: tuple[float, float]) -> float:
    """Capture pixels from the spot at which :func:`dark_level` reads the laser's glare: glare falls with the
    distance, so the median over the farthest pixels holds its value at their median distance, and subtracting the
    dark level takes that much glare out of every pixel of the capture."""
    radius, far = dark_region(pattern, centre)
    return float(radius[far].median())


def dark_surface(dark_frame: torch.Tensor) -> torch.Tensor:
    """(3, H, W) linear light (sRGB, as :func:`beam_profile` reads a capture): a quadratic surface per channel
    fitted to a dark frame. A dark room's light varies on the scale of the frame (a gradient, the lens's fall-off
    towards the corners), a capture's noise from pixel to pixel. Fitted by :func:`summed_least_squares`: LAPACK's
    lstsq read one dark frame to four different surfaces in 40 calls on one thread, and a calibration of camsim's
    halo case with dark frames fitted its halo exponent anywhere from 2.0483 to 2.0485 from run to run
    (docs/bench/session101/halo_repeatability.txt)."""
    light = srgb_to_linear(dark_frame)
    _, height, width = light.shape
    ys, xs = torch.meshgrid(
        torch.linspace(-0.5, 0.5, height, dtype=torch.float64),
        torch.linspace(-0.5, 0.5, width, dtype=torch.float64),
        indexing="ij",
    )
    terms = torch.stack([torch.ones_like(xs), xs, ys, xs * xs, xs * ys, ys * ys]).reshape(6, -1).T
    coefficients = torch.stack(
        [summed_least_squares(terms, channel) for channel in light.reshape(3, -1)], dim=1
    )
    return (terms @ coefficients).T.reshape(3, height, width)


# the room's gradient is read beyond this share of the largest distance a pixel is mirrored about the spot from:
# nearer, the beam's steep light turns any error in the spot's centre into a false gradient
GRADIENT_MIN_RADIUS_SHARE = 0.3
# fewest mirrored pixels the room's gradient is read from; with fewer (a spot at the frame's edge, a capture mostly
# saturated) the room is read as one level
MIN_GRADIENT_PIXELS = 64
# linear light of half an 8-bit step at black: a channel's light is weighed against at least this much
DARKEST_LIGHT = 0.5 / 255.0 / 12.92


class MirroredPairs(NamedTuple):
    light: torch.Tensor  # (3, H, W) the capture in linear light (sRGB)
    mirrored: torch.Tensor  # (3, H, W) its light at each pixel's mirror about the spot, sampled bilinearly
    dx: torch.Tensor  # (H, W) each pixel's offset from the spot's centre, x
    dy: torch.Tensor  # (H, W) and y
    # (H, W) bool: mirror in the frame, neither saturated, beyond the share of the distance
    usable: torch.Tensor


def mirrored_pairs(capture: torch.Tensor, centre: tuple[float, float]) -> MirroredPairs | None:
    """The capture's pixels and their mirrors under the point reflection ``p -> 2c - p`` about the spot's centre
    ``c`` (:func:`room_gradient` reads the room's gradient from their difference); None where fewer than
    ``MIN_GRADIENT_PIXELS`` are usable: mirror in the frame, beyond ``GRADIENT_MIN_RADIUS_SHARE`` of the largest
    mirrored distance, neither saturated."""
    light = srgb_to_linear(capture)
    _, height, width = light.shape
    ys, xs = torch.meshgrid(
        torch.arange(height, dtype=torch.float64), torch.arange(width, dtype=torch.float64), indexing="ij"
    )
    dx, dy = xs - centre[0], ys - centre[1]
    mirror_x, mirror_y = centre[0] - dx, centre[1] - dy
    # grid_sample with align_corners=True: -1 and 1 are the border pixels' centres
    grid = torch.stack([2 * mirror_x / max(width - 1, 1) - 1, 2 * mirror_y / max(height - 1, 1) - 1], dim=-1)
    saturated = (capture >= SATURATED).any(0)
    mirrored, saturated_mirror = (
        F.grid_sample(image[None], grid[None], mode="bilinear", padding_mode="border", align_corners=True)[0]
        for image in (light, saturated[None].double())
    )
    inside = (mirror_x >= 0) & (mirror_x <= width - 1) & (mirror_y >= 0) & (mirror_y <= height - 1)
    if not bool(inside.any()):
        return None
    radius = torch.hypot(dx, dy)
    usable = inside & ~saturated & (saturated_mirror[0] == 0)
    usable &= radius >= GRADIENT_MIN_RADIUS_SHARE * float(radius[inside].max())
    if int(usable.sum()) < MIN_GRADIENT_PIXELS:
        return None
    return MirroredPairs(light, mirrored, dx, dy, usable)


def room_gradient(capture: torch.Tensor, centre: tuple[float, float]) -> torch.Tensor | None:
    """(3, H, W) linear light (sRGB, as :func:`beam_profile` reads a capture): the dark room's linear gradient
    about the spot's centre ``c``, read from a capture alone; None where too few pixels read it.

    A laser's beam, bloom and glare are even under the point reflection ``p -> 2c - p`` about the spot (an
    elliptical beam too), a room's linear gradient is odd: ``L(p) - L(2c - p) = 2 g . (p - c)`` over pixels whose
    mirror lies in the frame, beyond ``GRADIENT_MIN_RADIUS_SHARE`` of the largest mirrored distance, neither
    saturated. The mirror is sampled bilinearly, and an error ``e`` in the spot's centre, which moves the even light
    by ``e . grad L`` and so reads as odd, is fitted beside ``g`` (per channel, its regressors the even light's
    gradient). The room's light comes from its sources through one fall-off in every channel, so ``g`` is each
    channel's level times one relative gradient, and each channel's odd light is weighed against the light it holds
    there: where the laser's glare is bright, its small asymmetries (demosaicing, the mirror's interpolation)
    outweigh the room's slope, which the fainter channels then read (per channel and unweighted, camsim's glare case
    read the laser channel's gradient worse than one level on two draws of five, docs/bench/session96.md). The
    room's even part (a lens's fall-off) cannot be told from the glare and stays in the level."""
    pairs = mirrored_pairs(capture, centre)
    if pairs is None:
        return None
    light, mirrored, dx, dy, use = pairs
    count = int(use.sum())
    even = 0.5 * (light + mirrored)
    grad_y, grad_x = torch.gradient(even, dim=(1, 2))
    _, far = dark_region(capture, centre)
    level = far_median(light, far)
    held = (even - level).clamp(min=0.0) + level + DARKEST_LIGHT
    design, odd = [], []
    for channel in range(3):
        weight = 1.0 / held[channel][use]
        columns = torch.zeros((count, 8), dtype=torch.float64)
        columns[:, 0], columns[:, 1] = level[channel, 0, 0] * dx[use], level[channel, 0, 0] * dy[use]
        columns[:, 2 + 2 * channel], columns[:, 3 + 2 * channel] = grad_x[channel][use], grad_y[channel][use]
        design.append(columns * weight[:, None])
        odd.append(0.5 * (light[channel] - mirrored[channel])[use] * weight)
    relative = summed_least_squares(torch.cat(design), torch.cat(odd))[:2]
    return level * (relative[0] * dx + relative[1] * dy)


def summed_least_squares(design: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """(k,) least-squares solution of ``design @ x = target`` by its normal equations, their sums taken by torch's
    reductions. LAPACK's lstsq sums in an order that follows the BLAS's threads (and, on one thread, the memory it
    is given), so the same capture read twice differed in its last bits, and a calibration reading it in its fit
    moved by 5e-7 relative when only held-out captures changed (``test_heldout_invariance.py``)."""
    columns = design.shape[1]
    normal = torch.empty((columns, columns), dtype=design.dtype)
    for i in range(columns):
        for j in range(i, columns):
            normal[i, j] = normal[j, i] = (design[:, i] * design[:, j]).sum()
    moment = torch.stack([(design[:, i] * target).sum() for i in range(columns)])
    # a column of zeros (a channel whose even light is flat) leaves the system singular: the minimum-norm solution
    return torch.linalg.pinv(normal) @ moment


def dark_field(
    capture: torch.Tensor, dark_frame: torch.Tensor | None, centre: tuple[float, float]
) -> torch.Tensor:
    """(3, H, W) encoded: the capture's dark level at every pixel, :func:`dark_level` where it is read. The room's
    light departs from its level as the dark frame's :func:`dark_surface` (the capture repeated with the laser off,
    as beam profilers record one) departs from its own median there, or, without one, as the capture's
    :func:`room_gradient` does: the capture, that departure taken out, is read as a capture of a uniform room (its
    median holding the glare at :func:`dark_level_radius`, which the physical model's halo adds back), and the
    departure put back. Read as one level, a room's gradient is laser light at the gain between the frames and the
    capture (tens to a hundred): it stood in for camsim's glare, which went unnamed on the draws of its halo case
    without a dark frame, and was named on the same draws with one (docs/bench/session79.md, session96.md).
    Subtracted whole (the surface, no glare added back), the dark frame leaves the capture's faint glare a few noise
    deviations above it, which the beam then reads pixel by pixel, noise and all, times the gain, where the halo had
    modelled it: on camsim's glare case the halo was named on fewer draws (docs/bench/session80.md)."""
    if dark_frame is None:
        surface = room_gradient(capture, centre)
        if surface is None:
            return dark_level(capture, centre).expand_as(capture)
    elif dark_frame.shape != capture.shape:
        raise ValueError(
            f"a dark frame must have its capture's shape {tuple(capture.shape)}, got {tuple(dark_frame.shape)}"
        )
    else:
        surface = dark_surface(dark_frame)
    _, far = dark_region(capture, centre)
    departure = surface - far_median(surface, far)
    # read in linear light: the median commutes with the tone curve, so this is dark_level of the flattened capture
    level = far_median((srgb_to_linear(capture) - departure).clamp(0.0, 1.0), far)
    return linear_to_srgb((level + departure).clamp(min=0.0))


# -- image operations --------------------------------------------------------------------------------------------


def median(values: torch.Tensor, dim: int = -1) -> torch.Tensor:
    """The median along ``dim``, the mean of the two middle values when their number is even (numpy's, where
    ``torch.median`` returns the lower one)."""
    ordered = values.sort(dim=dim).values
    count = values.shape[dim]
    upper = ordered.narrow(dim, count // 2, 1)
    if count % 2:
        return upper.squeeze(dim)
    return ((ordered.narrow(dim, count // 2 - 1, 1) + upper) / 2).squeeze(dim)


# the median absolute deviation of a normal distribution over its standard deviation: the normal quantile at 3/4
NORMAL_MAD = 0.6744897501960817


def robust_spread(values: torch.Tensor) -> torch.Tensor:
    """Per row of ``(rows, n)``: the median absolute deviation about the median, scaled to a normal's deviation."""
    centred = values - median(values, dim=1).unsqueeze(1)
    return median(centred.abs(), dim=1) / NORMAL_MAD


def fill_holes(mask: torch.Tensor) -> torch.Tensor:
    """(H, W) bool: ``mask`` with every background region the frame's border cannot reach through background
    (4-connected) filled in."""
    background = ~mask
    reached = torch.zeros_like(mask)
    reached[0], reached[-1], reached[:, 0], reached[:, -1] = (
        background[0],
        background[-1],
        background[:, 0],
        background[:, -1],
    )
    while True:
        grown = reached.clone()
        grown[1:] |= reached[:-1]
        grown[:-1] |= reached[1:]
        grown[:, 1:] |= reached[:, :-1]
        grown[:, :-1] |= reached[:, 1:]
        grown &= background
        if torch.equal(grown, reached):
            return ~reached
        reached = grown


def distance_to_background(mask: torch.Tensor, pairs: int = 1 << 18) -> torch.Tensor:
    """(H, W) float64: each ``mask`` pixel's Euclidean distance to the nearest pixel outside it (0 outside).

    The nearest outside pixel always borders the mask (a step from it towards the pixel comes nearer), so only
    those are searched, in blocks of at most ``pairs`` (mask pixel, border pixel) pairs; squared distances of whole
    pixels are exact in float64, so is their square root."""
    if bool(mask.all()):
        raise ValueError("a mask covering the whole frame has no pixel outside it to measure a distance to")
    out = torch.zeros(mask.shape, dtype=torch.float64)
    if not bool(mask.any()):
        return out
    padded = F.pad(mask[None, None].double(), (1, 1, 1, 1))
    beside = F.max_pool2d(padded, 3, stride=1)[0, 0] > 0  # a mask pixel within the 3x3 around
    edge = torch.nonzero(beside & ~mask).double()
    inside = torch.nonzero(mask)
    nearest = torch.cat(
        [
            ((block[:, None, :] - edge[None, :, :]) ** 2).sum(-1).amin(1)
            for block in inside.double().split(max(1, pairs // len(edge)))
        ]
    )
    out[inside[:, 0], inside[:, 1]] = nearest.sqrt()
    return out


def line_fit(x: torch.Tensor, y: torch.Tensor) -> tuple[float, float]:
    """Least-squares ``(slope, offset)`` of ``y = slope x + offset``."""
    design = torch.stack([x, torch.ones_like(x)], dim=1)
    solution = torch.linalg.lstsq(design, y.unsqueeze(1), driver="gelsd").solution.squeeze(1)
    return float(solution[0]), float(solution[1])


# -- the beam ------------------------------------------------------------------------------------------------------

# a saturated capture reads a few grey levels below 255 where JPEG rings in its flat white: 248 and above counts
SATURATED = 247.5 / 255.0
# the capture's noise is estimated, and removed, on the scale of a few pixels: a beam profile is smooth there
BEAM_SMOOTHING_PX = 1.0
# a value counts as laser light when it stands this many noise deviations above the capture's dark level
NOISE_FLOOR_SIGMAS = 3.0
# the beam's edge whose fall-off is continued below the noise floor: measured light between these many floors
# (from twice the floor: pixels just above it are the ones noise lifted there, a fall-off read from them is too flat)
EDGE_FLOORS = (2.0, 16.0)
# fewest edge pixels a fall-off is fitted to (a line through log light vs r^2 from fewer is noise)
MIN_EDGE_PIXELS = 6


class BeamReading(NamedTuple):
    # (3, H, W) encoded values: the beam without the capture's noise, continued below its floor
    profile: torch.Tensor
    # (H, W) bool: where the laser's own channel stands above the capture's noise floor
    measured: torch.Tensor


def beam_profile(pattern: torch.Tensor, dark: torch.Tensor, centre: tuple[float, float]) -> BeamReading:
    """The laser's beam profile as the capture measured it, without the capture's noise (encoded values), and
    where the capture measured it.

    The capture records the beam plus its own dark noise (photon noise of the dark room's light, read noise, 8-bit
    steps, compression). Only the beam grows with the laser's power: read as laser light and scaled by the power
    ratio between the frames and the capture (tens, for a beam-profile exposure), the noise would be amplified
    into the frames too. So the capture is smoothed over ``BEAM_SMOOTHING_PX`` (a beam profile varies slowly on
    that scale, pixel noise does not), and values within ``NOISE_FLOOR_SIGMAS`` noise deviations of the dark level
    ``dark`` (encoded: one level per channel, (3, 1, 1), or a field, (3, H, W); the noise is the robust spread of
    the capture about its smoothed self in the outer half, plus the 8-bit step) are not read as measured light. The
    beam does not end at that floor: at the power ratio, its light below the floor lights the frames far around
    the spot. There it is continued with the fall-off of its measured edge (light ``EDGE_FLOORS`` floors above the
    dark level): in the laser's own channel (the one holding the most light), a Gaussian in the distance from the
    spot, ``exp(a - r^2 / (2 s^2))``, fitted in linear light (sRGB) and capped at the floor.

    A laser is narrowband, so every part of its light (beam, bloom, glare) reaches the other two channels in one
    fixed ratio, the laser's colour. Wherever the laser's channel is unsaturated, they are its beam times that
    ratio: the slope of one on the other through the origin, where both measure the beam unsaturated (the
    brightest, most precisely measured light leads it). Their own readings hold more than the laser's light
    there: demosaicing and colour compression bleed the laser channel's steep edge into them, which the frames,
    where that channel clips, do not repeat at the power ratio; and they sink below their floors far nearer the
    spot. Read on their own (session 16 and before), a red laser's blue channel held 2-11 times its colour share
    10-25 px from the spot, and its faint edge, continued on its own, held the floor over the whole frame: tens of
    grey levels of light of the wrong colour at the power ratio, which the fit answered with a low gain and a
    glare for the spot (camsim halo case, docs/bench/camsim_session17.md). A power-law glare
    beyond the continued beam is the halo's to model."""
    _, height, width = pattern.shape
    # scipy.ndimage.gaussian_filter's cut at four deviations, borders replicated (its mode="nearest")
    smooth = gaussian_spread(pattern[None], BEAM_SMOOTHING_PX, radius=int(4.0 * BEAM_SMOOTHING_PX + 0.5))[0]
    ys, xs = torch.meshgrid(
        torch.arange(height, dtype=torch.float64), torch.arange(width, dtype=torch.float64), indexing="ij"
    )
    radius = torch.hypot(xs - centre[0], ys - centre[1])
    flat_radius = radius.reshape(-1)
    # pixel noise: the robust spread of the capture about its smoothed self in the outer half (a smooth beam
    # there, whether faint or bright, leaves only the noise)
    detail = (pattern - smooth).reshape(3, -1)[:, flat_radius >= flat_radius.median()]
    noise = torch.sqrt(robust_spread(detail) ** 2 + 1.0 / (12.0 * 255.0**2))
    dark_linear = srgb_to_linear(dark)
    light = srgb_to_linear(smooth) - dark_linear
    floor = srgb_to_linear(dark + NOISE_FLOOR_SIGMAS * noise.reshape(3, 1, 1)) - dark_linear
    measured = light > floor
    beam = torch.where(measured, light, torch.zeros_like(light))
    laser = int(light.clamp(min=0.0).sum(dim=(1, 2)).argmax())
    unsaturated = smooth < SATURATED
    low, high = EDGE_FLOORS[0] * floor[laser], EDGE_FLOORS[1] * floor[laser]
    edge = (light[laser] > low) & (light[laser] < high) & unsaturated[laser]
    slope, offset = 0.0, 0.0
    if int(edge.sum()) >= MIN_EDGE_PIXELS:
        slope, offset = line_fit(radius[edge] ** 2, torch.log(light[laser][edge]))
    if slope < 0.0:
        tail = torch.minimum(torch.exp(offset + slope * radius**2), floor[laser])
        beam[laser] = torch.where(measured[laser], beam[laser], tail)
    else:
        logger.warning(
            "laser capture channel %d (the laser's): %d pixels on the beam's edge (at least %d needed), falling off "
            "with distance from the spot at a slope of %.3g (negative needed), so the beam is not continued below "
            "the noise floor; the frames see no laser light there",
            laser,
            int(edge.sum()),
            MIN_EDGE_PIXELS,
            slope,
        )
    for c in range(3):
        if c == laser:
            continue
        # the colour ratio, read where both channels measure the beam unsaturated
        both = measured[c] & measured[laser] & unsaturated[c] & unsaturated[laser]
        if int(both.sum()) < MIN_EDGE_PIXELS:
            logger.warning(
                "laser capture channel %d: %d pixels measure the beam unsaturated where the laser's own channel "
                "(%d) does too (fewer than %d), so it is not read in the laser's colour: its light below the noise "
                "floor is not continued, and the frames see none there",
                c,
                int(both.sum()),
                laser,
                MIN_EDGE_PIXELS,
            )
            continue
        ratio = (light[c][both] * light[laser][both]).sum() / (light[laser][both] ** 2).sum()
        beam[c] = torch.where(unsaturated[laser], ratio * beam[laser], beam[c])
    return BeamReading(linear_to_srgb(beam + dark_linear), measured[laser])


def saturated_depth(pattern: torch.Tensor) -> torch.Tensor:
    """(3, H, W): per channel, the distance (working pixels) from each saturated pixel of the capture to the
    nearest unsaturated one (0 outside the saturated area)."""
    # holes left by compression noise are closed: a saturated area has no unsaturated islands
    return torch.stack([distance_to_background(fill_holes(c)) for c in pattern >= SATURATED])


def core_continued(
    pattern: torch.Tensor,
    dark: torch.Tensor,
    core_depth: torch.Tensor,
    core_radius: torch.Tensor,
    core_sigma_ref_px: float | torch.Tensor,
    inner_core_peak: float | torch.Tensor = 0.0,
    inner_core_sigma_ref_px: float | torch.Tensor = 1.0,
) -> torch.Tensor:
    """Laser light per unit power from the decoded capture ``pattern``: its decoded dark level ``dark`` removed, its
    saturated core continued as a Gaussian beam of width ``core_sigma_ref_px``: a channel saturated out to radius
    ``R`` (``core_radius``, from its saturated area) rises at depth ``d`` (``core_depth``, the distance to the
    nearest unsaturated pixel, capped at ``R``) by ``exp((2 R d - d^2) / (2 sigma^2))``, the Gaussian's ``exp((R^2 -
    r^2) / (2 sigma^2))`` written with the distance to the core's edge, so saturated areas of any shape are followed
    (lengths in reference pixels).

    ``inner_core_peak`` > 0 adds a narrower beam at the core's centre, ``inner_core_peak`` times the saturated level
    there, of width ``s`` = ``inner_core_sigma_ref_px``, less its value at the edge: ``exp(-(R - d)^2 / (2 s^2)) -
    exp(-R^2 / (2 s^2))`` times that. A spot is a focused core inside a wider skirt (defocus, a lens's point
    spread); a capture saturated out into the skirt shows the skirt's edge only, whose Gaussian continued inwards
    misses the core's steeper rise."""
    depth = torch.minimum(core_depth, core_radius)
    rise = (2.0 * core_radius * depth - depth**2) / (2.0 * core_sigma_ref_px**2)
    continued = torch.exp(rise.clamp(max=50.0))
    spread = 2.0 * inner_core_sigma_ref_px**2
    # 0 at the edge (depth 0) and outside the core
    inner = torch.exp(-((core_radius - depth) ** 2) / spread) - torch.exp(-(core_radius**2) / spread)
    return (pattern - dark).clamp(min=0.0) * (continued + inner_core_peak * inner)


@dataclass(frozen=True)
class CaptureReading:
    """Everything the physical laser blinding reads from a capture at one frame size (:func:`read_capture`)."""

    centre: tuple[float, float]  # the spot, (x, y) pixels
    dark: torch.Tensor  # (3, H, W) encoded dark level (:func:`dark_field`)
    beam: torch.Tensor  # (3, H, W) encoded beam profile, continued below the noise floor
    measured: torch.Tensor  # (H, W) bool: where the capture measured the laser's light
    core_depth: torch.Tensor  # (3, H, W) reference pixels into each channel's saturated core
    core_radius: torch.Tensor  # (3, 1, 1) reference pixels: each channel's saturated area as a disc's radius
    dark_radius: float  # reference pixels from the spot at which the dark level was read


def read_capture(capture: torch.Tensor, dark_frame: torch.Tensor | None = None) -> CaptureReading:
    """A capture ``(3, H, W)`` in [0, 1] (float64) read as the calibration reads its pairs' captures: its spot, dark
    level (:func:`dark_field`, from ``dark_frame``, the capture repeated with the laser off, where there is one),
    beam profile, saturated core, and the dark level's distance."""
    height, width = capture.shape[-2:]
    to_reference = REFERENCE_SIZE / max(height, width)
    centre = pattern_centre(capture)
    dark = dark_field(capture, dark_frame, centre)
    depth = saturated_depth(capture) * to_reference
    reading = beam_profile(capture, dark, centre)
    return CaptureReading(
        centre=centre,
        dark=dark,
        beam=reading.profile,
        measured=reading.measured,
        core_depth=depth,
        core_radius=torch.sqrt((depth > 0).sum(dim=(1, 2)).double() / math.pi).reshape(3, 1, 1)
        * to_reference,
        dark_radius=dark_level_radius(capture, centre) * to_reference,
    )
