"""Sensor-physics kernels shared by the attack transforms and by ``lerobot-phantom-calibrate``.

The paper's simulations are image-space formulas (alpha blends, a fixed band of rows, a uniform line blur). Real
cameras differ in ways these kernels model: light adds in linear irradiance and clips at the sensor's full well
before the gamma curve, laser glare falls off as a power law, auto-exposure darkens the whole frame, a rolling
shutter lights the rows whose exposure window overlaps a laser pulse, a resonating gyroscope moves the image
sinusoidally (so the blur path dwells at its ends), and dropped rows flip the Bayer colour-filter phase.

Everything here is pure torch, differentiable where it makes sense, dtype-agnostic (float32 for the transforms,
float64 for fitting) and batched: per-sample parameters are tensors with a leading batch dim (or scalars).
Images are ``(B, 3, H, W)`` in [0, 1].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
import torch.nn.functional as F

# ---------------------------------------------------------------------------------------------------------------
# tone curves


def srgb_to_linear(x: torch.Tensor) -> torch.Tensor:
    """sRGB-encoded values in [0, 1] -> linear light (IEC 61966-2-1)."""
    x = x.clamp(0.0, 1.0)
    return torch.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(x: torch.Tensor) -> torch.Tensor:
    """Linear light in [0, 1] -> sRGB-encoded values (values outside [0, 1] are clipped first)."""
    x = x.clamp(0.0, 1.0)
    return torch.where(x <= 0.0031308, 12.92 * x, 1.055 * x.clamp(min=0.0031308) ** (1.0 / 2.4) - 0.055)


# x ** n at x = 0 has an undefined derivative in n (0 * log 0): the darkest light a shoulder curve models
SHOULDER_TINY = 1e-12


@dataclass(frozen=True)
class ShoulderCurve:
    """A camera tone curve whose highlights roll off instead of clipping (film, "filmic" ISP tone mapping): the
    normalised log-logistic (Naka-Rushton) response under a display power law,

        u = (1 + s) x**n / (1 + s x**n),     pixel = u ** (1 / (n gamma)),

    ``s = shoulder`` >= 0 its strength (0: the power law ``gamma``), ``n = exponent`` > 0 the knee's sharpness; the
    sensor's saturation (x = 1) stays the file's white. ``lerobot-phantom-calibrate`` fits it as ``tone_shoulder``
    (calibration/tone.py holds the physics); the attacks take it wherever they take a ``gamma``. Fields may be
    tensors (a fit differentiates through them)."""

    shoulder: float | torch.Tensor
    exponent: float | torch.Tensor = 1.0
    gamma: float | torch.Tensor = 1.0

    def decode(self, encoded: torch.Tensor) -> torch.Tensor:
        """Encoded pixel values in [0, 1] -> linear light in [0, 1] (closed form: the curve is invertible)."""
        s, n = self.shoulder, self.exponent
        u = encoded.clamp(SHOULDER_TINY, 1.0) ** (self.gamma * n)
        return (u / (1.0 + s - s * u)) ** (1.0 / n)

    def encode(self, linear: torch.Tensor) -> torch.Tensor:
        """Linear light -> encoded pixel values (light beyond the sensor's saturation is clipped first)."""
        s, n = self.shoulder, self.exponent
        xn = linear.clamp(SHOULDER_TINY, 1.0) ** n
        return ((1.0 + s) * xn / (1.0 + s * xn)) ** (1.0 / (n * self.gamma))


Tone = float | torch.Tensor | ShoulderCurve | None


def tone_options(
    gamma: float | None, shoulder: float | None, shoulder_exponent: float, *, owner: str
) -> Tone:
    """An attack's tone options as one curve: ``gamma`` alone, or the shoulder under the display power ``gamma``
    (None: 1, the pixel values themselves). ``owner`` names the attack in the error."""
    if shoulder is None:
        if float(shoulder_exponent) != 1.0:
            raise ValueError(
                f"{owner}: shoulder_exponent={shoulder_exponent!r} needs shoulder= (a number >= 0)"
            )
        return gamma
    display = 1.0 if gamma is None else float(gamma)
    if not (
        math.isfinite(float(shoulder))
        and float(shoulder) >= 0.0
        and float(shoulder_exponent) > 0.0
        and display > 0.0
    ):
        raise ValueError(
            f"{owner}: shoulder={shoulder!r}, shoulder_exponent={shoulder_exponent!r}, gamma={gamma!r}; valid: a "
            "finite shoulder >= 0 (0: no shoulder), an exponent > 0 and a display gamma > 0 (None: 1)"
        )
    return ShoulderCurve(float(shoulder), float(shoulder_exponent), display)


def decode(x: torch.Tensor, gamma: Tone) -> torch.Tensor:
    """Encoded pixel values -> linear light: sRGB when ``gamma`` is None, a pure power law ``x ** gamma``, or a
    ``ShoulderCurve``'s inverse."""
    if gamma is None:
        return srgb_to_linear(x)
    if isinstance(gamma, ShoulderCurve):
        return gamma.decode(x)
    return x.clamp(min=0.0) ** _as(gamma, x)


def encode(x: torch.Tensor, gamma: Tone) -> torch.Tensor:
    """Inverse of ``decode`` (clips to [0, 1] first: a sensor cannot record more than its full well)."""
    if gamma is None:
        return linear_to_srgb(x)
    if isinstance(gamma, ShoulderCurve):
        return gamma.encode(x)
    return x.clamp(1e-12, 1.0) ** (1.0 / _as(gamma, x))


def _as(value: float | torch.Tensor, like: torch.Tensor) -> torch.Tensor:
    """A scalar or per-sample ``(B,)`` value broadcastable against ``like`` of shape ``(B, ...)``."""
    t = torch.as_tensor(value, dtype=like.dtype, device=like.device)
    if t.ndim == 1 and like.ndim > 1:
        t = t.reshape(-1, *([1] * (like.ndim - 1)))
    return t


# ---------------------------------------------------------------------------------------------------------------
# light injection (laser blinding, light projection)


def inject_linear_light(
    x: torch.Tensor,
    light: torch.Tensor,
    *,
    auto_exposure: float | torch.Tensor = 0.0,
    metered_light: torch.Tensor | None = None,
    meter_power: float = 0.0,
    meter_reads: str = "channel_mean",
    white: float | torch.Tensor = 1.0,
    gamma: Tone = None,
    colour_correction: torch.Tensor | None = None,
) -> torch.Tensor:
    """Add ``light`` (linear irradiance, broadcastable to ``x``) to the scene in linear light, clip, re-encode.

    ``auto_exposure`` a: the camera's gain drops as ``1 / (1 + a * mean(metered_light))`` (default: the injected
    light), darkening the whole frame; ``meter_power`` a, its alternative: the exposure scales by ``k ** a``, ``k``
    the exposure at which the frame's clipped mean level equals the scene's over :func:`meter_pixels`
    (:func:`metered_exposure`), each pixel's light read as ``meter_reads`` (:func:`meter_light`);
    ``white``: linear level at which the sensor saturates; ``gamma``: None = the sRGB tone curve, a number = a
    power law (1 = compose the encoded values); ``colour_correction``: a (3, 3) matrix the camera mixes its clipped
    raw channels with (``light`` is then raw light, the scene is taken to the raw channels by its inverse).
    """
    if meter_power > 0.0 and (metered_light is not None or bool(torch.as_tensor(auto_exposure).ne(0).any())):
        raise ValueError(
            "meter_power and auto_exposure (with metered_light) are two auto-exposures: give one"
        )
    scene = decode(x, gamma)
    if colour_correction is not None:
        scene = mix_channels(torch.linalg.inv(colour_correction.to(torch.float64)), scene)
    if meter_power > 0.0:
        total = scene + light
        flat = (-1, *([1] * (x.ndim - 1)))
        read = meter_pixels(*x.shape[-2:]).to(x.device)
        exposure = metered_exposure(
            meter_light(total, meter_reads, -3).flatten(-2)[..., read],
            meter_light(scene, meter_reads, -3).flatten(-2)[..., read],
        )
        total = total * exposure.reshape(flat) ** meter_power
    else:
        metered = light if metered_light is None else metered_light
        mean_light = metered.reshape(metered.shape[0], -1).mean(dim=1).reshape(-1, *([1] * (x.ndim - 1)))
        total = (scene + light) / (1.0 + _as(auto_exposure, scene) * mean_light)
    total = torch.minimum(total.clamp(min=0.0), _as(white, total))
    if colour_correction is not None:
        total = mix_channels(colour_correction.to(torch.float64), total).clamp(0.0, 1.0)
    return encode(total, gamma)


METER_PIXELS = 1024
"""The pixels an auto-exposure meter reads in a frame (:func:`meter_pixels`): the calibration's frame model and the
physical laser blinding meter the same ones."""


METER_READS = ("channel_mean", "luminance")
"""What an auto-exposure meter reads of a pixel's light (:func:`meter_light`)."""

LUMINANCE_WEIGHTS = (0.2126, 0.7152, 0.0722)
"""Rec. 709 luminance weights of the red, green and blue channels."""


def check_meter_reads(reads: str) -> str:
    """``reads`` if it is one of ``METER_READS``; else a ValueError naming them."""
    if reads not in METER_READS:
        raise ValueError(f"meter_reads {reads!r}; valid: {', '.join(METER_READS)}")
    return reads


def meter_light(light: torch.Tensor, reads: str, dim: int) -> torch.Tensor:
    """The light a meter reads at each pixel of ``light``, whose channels lie along ``dim``: their mean
    (``"channel_mean"``) or their luminance (``"luminance"``, Rec. 709 weights). An auto-exposure commonly meters
    the luminance of its sensor's raw channels, before the ISP's matrix mixes them (camsim's does); on such a
    colour-correcting camera, whose raw light the calibration models, the channel mean weighed a narrowband
    laser's channel wrongly against the scene's, and the matrix's take ran to its bound in its place
    (docs/bench/session95.md)."""
    if check_meter_reads(reads) == "channel_mean":
        return light.mean(dim)
    shape = [1] * light.ndim
    shape[dim] = 3
    weights = torch.tensor(LUMINANCE_WEIGHTS, dtype=light.dtype, device=light.device).reshape(shape)
    return (light * weights).sum(dim)


def meter_pixels(height: int, width: int, count: int = METER_PIXELS) -> torch.Tensor:
    """Flat indices of the pixels a meter reads in a ``height`` x ``width`` frame: one at the middle of each of
    ``count`` equal runs of the frame in raster order, a regular sample of rows and columns (every pixel of a frame
    with no more than ``count``). While the fit metered a random third of camsim's pixels and the attack every pixel,
    the attack stood 1.31-5.32 grey levels RMS from its written model on four auto-exposed draws
    (docs/bench/session92/blinding_attack_parity_b6c20ea.txt; 0.000 on the same pixels)."""
    count = min(count, height * width)
    centres = (torch.arange(count, dtype=torch.float64) + 0.5) * (height * width / count)
    return centres.floor().long()


def metered_exposure(total: torch.Tensor, scene: torch.Tensor, steps: int = 12) -> torch.Tensor:
    """``(n,)``: per frame, the exposure ``k`` at which a meter reading the sensor's clipped light reads the blinded
    frame as it read the clean one, ``mean(min(k total, 1)) = mean(min(scene, 1))``, over the pixels of ``(n, P)``
    light (a channel's mean per pixel). The reading is concave and piecewise linear in ``k``: Newton steps from
    ``k = 1`` (differentiable through the iterations) until they move ``k`` by rounding only, at most ``steps``;
    ``k`` kept in [1e-4, 10]. Each frame stops at its own last step, so its ``k`` does not depend on the frames
    metered beside it: stopped together, a frame took the steps another needed, its last bits moved by rounding, and
    a calibration's fit moved when only held-out frames changed (``test_heldout_invariance.py``, session 96)."""
    target = scene.clamp(max=1.0).mean(1)
    k = torch.ones(len(total), dtype=total.dtype, device=total.device)
    settled = torch.zeros(len(total), dtype=torch.bool, device=total.device)
    for _ in range(steps):
        lit = (k[:, None] * total < 1.0).to(total.dtype)
        reading = torch.minimum(k[:, None] * total, torch.ones_like(total)).mean(1)
        slope = (total * lit).mean(1).clamp(min=1e-9)
        stepped = (k - (reading - target) / slope).clamp(1e-4, 10.0)
        # on a linear piece Newton lands on the root: later steps move it by rounding only
        moved_by_rounding = (stepped - k).abs() <= 8 * torch.finfo(k.dtype).eps * k
        k = torch.where(settled, k, stepped)
        settled = settled | moved_by_rounding
        if bool(settled.all()):
            break
    return k


def raw_light_per_stored(
    colour_correction: torch.Tensor, raw_colour: torch.Tensor, channel: int
) -> torch.Tensor:
    """(3,) a laser's raw light in each channel per unit of the light its own ``channel`` stores, under a camera's
    (3, 3) ``colour_correction``: the laser's raw colour ``raw_colour`` (1 in its own channel) over the share of it
    the matrix leaves in that channel. A capture through the matrix stores the laser's fainter channels at 0 (pushed
    below it), so its own channel, read this way, is the only measure of the laser's raw light."""
    stored_share = (colour_correction.to(raw_colour.dtype) @ raw_colour)[channel]
    return raw_colour / stored_share.clamp(min=1e-6)


def correction_matrix(takes: torch.Tensor) -> torch.Tensor:
    """(3, 3) colour correction matrix from ``takes`` (3,): raw channel j's light taken out of each other channel by
    ``takes[j]``, each row summing to 1 (white stays white). Consumer cameras' matrices undo their colour filters'
    overlap: a diagonal above 1, negative off-diagonals."""
    takes = takes.to(torch.float64)
    return torch.diag(takes.sum() - takes + 1.0) - (1.0 - torch.eye(3, dtype=torch.float64)) * takes


def check_colour_correction(values, owner: str) -> tuple[float, ...] | None:
    """``values`` as a colour correction matrix (9 numbers, row-major, each row summing to 1), or None."""
    if values is None:
        return None
    matrix = torch.tensor(values, dtype=torch.float64)
    if matrix.numel() != 9 or not torch.allclose(
        matrix.reshape(3, 3).sum(1), torch.ones(3, dtype=torch.float64), atol=1e-6
    ):
        raise ValueError(
            f"{owner}: colour_correction {values}; valid: None or 9 numbers, a row-major 3x3 matrix whose rows "
            "sum to 1"
        )
    return tuple(float(v) for v in matrix.reshape(-1))


# the stored level at or below which a captured pattern's channel reads as black. A colour-correcting camera's matrix
# pushes a primary's fainter channels below 0, stored at 0, and the sensor's read noise lifts them: a 12-bit sensor's
# black noise of ~5e-4 of white reaches 8 grey levels under a 2.2 power law (2 under sRGB's linear toe). A channel
# truly just above black after the matrix is a coincidence of its raw light and the matrix's leak, so a wide black
# level costs little (docs/bench/session99.md)
PATTERN_BLACK_LEVEL = 8 / 255


def captured_light_to_raw(
    light: torch.Tensor, pattern: torch.Tensor, colour_correction: torch.Tensor, *, channel_dim: int = -3
) -> torch.Tensor:
    """A projector pattern captured through a camera's (3, 3) ``colour_correction``, ``light`` (decoded to linear
    light in the stored channels) -> the light in the raw channels; ``pattern``: its encoded values, same shape.

    A channel the capture stores at black (``PATTERN_BLACK_LEVEL``) is read as no light of its own, the others
    through the inverse of the matrix's block for them: the least light the capture allows, exact for a primary
    that only its own colour filter sees. The whole matrix's inverse reads such a channel as just at 0 after the
    matrix, so it puts back the light the negative off-diagonals took out of it: a red primary comes back with
    green and blue light it never had."""
    correction = colour_correction.to(torch.float64)
    blocks = []
    for code in range(8):  # bit c set: channel c at black
        keep = torch.tensor([c for c in range(3) if not code >> c & 1], dtype=torch.long)
        block = torch.zeros(3, 3, dtype=torch.float64)
        if len(keep):
            rows, cols = torch.meshgrid(keep, keep, indexing="ij")
            block = block.index_put((rows, cols), torch.linalg.inv(correction[keep][:, keep]))
        blocks.append(block)
    at_black = (pattern <= PATTERN_BLACK_LEVEL).movedim(channel_dim, -1)
    code = (at_black.long() * torch.tensor([1, 2, 4], device=pattern.device)).sum(-1)
    matrices = torch.stack(blocks).to(light.dtype).to(light.device)[code]
    raw = (matrices @ light.movedim(channel_dim, -1)[..., None])[..., 0]
    return raw.movedim(-1, channel_dim)


def mix_channels(matrix: torch.Tensor, image: torch.Tensor) -> torch.Tensor:
    """``matrix`` (3, 3) applied to every pixel of a ``(..., 3, H, W)`` image, in the image's dtype."""
    return torch.einsum("ij,...jhw->...ihw", matrix.to(image.dtype), image)


def radial_distance(
    height: int, width: int, center: torch.Tensor, *, dtype=torch.float32, device=None
) -> torch.Tensor:
    """Distance in pixels of every pixel from ``center`` = ``(B, 2)`` (x, y) -> ``(B, 1, H, W)``."""
    ys = torch.arange(height, dtype=dtype, device=device).reshape(1, 1, height, 1)
    xs = torch.arange(width, dtype=dtype, device=device).reshape(1, 1, 1, width)
    center = center.to(dtype).reshape(-1, 2, 1, 1)
    return torch.sqrt((xs - center[:, 0:1]) ** 2 + (ys - center[:, 1:2]) ** 2)


def power_law_halo(
    radius: torch.Tensor,
    amplitude: float | torch.Tensor,
    exponent: float | torch.Tensor,
    scale: float | torch.Tensor,
) -> torch.Tensor:
    """Glare around a bright source: ``amplitude * (1 + r / scale) ** -exponent`` (finite at the centre)."""
    return _as(amplitude, radius) * (1.0 + radius / _as(scale, radius)) ** (-_as(exponent, radius))


def laser_spot_profile(
    radius: torch.Tensor,
    core_sigma: float | torch.Tensor,
    *,
    halo_amplitude: float | torch.Tensor = 0.0,
    halo_exponent: float | torch.Tensor = 2.0,
    halo_scale: float | torch.Tensor = 1.0,
) -> torch.Tensor:
    """Relative irradiance of a laser spot: Gaussian core plus a power-law glare ``h * (1 + r / r0) ** -k``.

    Scattering in the lens and on the sensor spreads a bright source far beyond its geometric image; measured
    glare falls off as a power of the distance rather than the Gaussian's exponential tail.
    """
    sigma = _as(core_sigma, radius)
    core = torch.exp(-0.5 * (radius / sigma) ** 2)
    halo = _as(halo_amplitude, radius) * (1.0 + radius / _as(halo_scale, radius)) ** (
        -_as(halo_exponent, radius)
    )
    return core + halo


def saturation_radius(
    peak: float,
    core_sigma: float,
    *,
    halo_amplitude: float = 0.0,
    halo_exponent: float = 2.0,
    halo_scale: float = 1.0,
    white: float = 1.0,
    max_radius: float = 1e4,
) -> float:
    """Radius (pixels) inside which ``peak * laser_spot_profile`` reaches the sensor's ``white`` level (0 if never)."""
    if peak <= white:
        return 0.0
    lo, hi = 0.0, max_radius
    for _ in range(80):  # bisection: the profile decreases monotonically with r
        mid = 0.5 * (lo + hi)
        r = torch.tensor([mid], dtype=torch.float64)
        value = peak * float(
            laser_spot_profile(
                r,
                core_sigma,
                halo_amplitude=halo_amplitude,
                halo_exponent=halo_exponent,
                halo_scale=halo_scale,
            )[0]
        )
        lo, hi = (mid, hi) if value >= white else (lo, mid)
    return 0.5 * (lo + hi)


def gaussian_spread(
    x: torch.Tensor, sigma_px: float | torch.Tensor, *, radius: int | None = None
) -> torch.Tensor:
    """Light spread over neighbouring pixels by a Gaussian point spread of standard deviation ``sigma_px`` pixels
    (one value, or ``(B,)`` per image) on ``(B, C, H, W)`` linear light; pixels beyond the border repeat the edge.

    ``radius`` is the kernel's half width (default 3 sigma): a fit passes the widest its bound allows, so the kernel's
    shape never depends on the value being fitted. Not torchvision's ``gaussian_blur``: calibration fits sigma by
    autograd, and torchvision takes it as a Python float. A spread of 0 is the identity."""
    batch, channels, height, width = x.shape
    sigma = _as(sigma_px, x).reshape(-1).expand(batch)
    if radius is None:
        radius = max(1, math.ceil(3.0 * float(sigma.max())))
    taps = torch.arange(-radius, radius + 1, dtype=x.dtype, device=x.device)
    # the narrowest kernel is a single tap: a spread of 0 divides by nothing
    kernel = torch.exp(-0.5 * (taps / sigma.clamp(min=1e-3)[:, None]) ** 2)
    kernel = (kernel / kernel.sum(dim=1, keepdim=True)).repeat_interleave(channels, dim=0)
    planes = F.pad(x.reshape(1, batch * channels, height, width), (radius,) * 4, mode="replicate")
    planes = F.conv2d(planes, kernel[:, None, None, :], groups=batch * channels)
    planes = F.conv2d(planes, kernel[:, None, :, None], groups=batch * channels)
    return planes.reshape(batch, channels, height, width)


def project_light(
    x: torch.Tensor,
    pattern: torch.Tensor,
    strength: float | torch.Tensor,
    *,
    albedo: bool = False,
    reflectance_floor: float | torch.Tensor = 0.0,
    crosstalk: torch.Tensor | None = None,
    white: float | torch.Tensor = 1.0,
    gamma: Tone = 1.0,
    projector_gamma: float | torch.Tensor | None = None,
    spread_px: float | torch.Tensor = 0.0,
    blend: bool = False,
    colour_correction: torch.Tensor | None = None,
) -> torch.Tensor:
    """Projector light on a surface seen by a camera: light adds, it never blends (``blend=True`` keeps the
    paper's blend, ``(1 - strength) * scene + strength * light``, with the other terms).

    The projected colour ``pattern`` (encoded, like an image; black = no light) reaches the camera as
    ``crosstalk @ rgb`` (3x3: the projector's primaries seen through the camera's filters), spread over
    ``spread_px`` pixels (``gaussian_spread``: a projector out of focus on the surface, the lens's point spread),
    scaled by ``strength`` and, with ``albedo``, by the surface's reflectance estimated from its colour
    (``scene + reflectance_floor``). The sum clips at ``white`` and is re-encoded; ``gamma`` as in ``decode``
    (1 = compose the encoded values). ``projector_gamma``: the pattern is the frame the projector is sent, turned
    into light by the projector's display transfer ``pattern ** projector_gamma``; None: the pattern is decoded
    like the scene, a capture of the projected light through this camera. ``colour_correction``: a (3, 3) matrix
    the camera mixes its raw channels with after the sensor: the light meets the surface's reflectance and the clip
    in the raw channels (the scene taken there by the matrix's inverse, a captured pattern by
    ``captured_light_to_raw``; ``crosstalk`` is then the camera's raw response to the primaries), and the matrix
    mixes the sum before the tone curve.
    """
    scene = decode(x, gamma)
    light = decode(pattern, gamma if projector_gamma is None else projector_gamma)
    if colour_correction is not None:
        scene = mix_channels(torch.linalg.inv(colour_correction.to(torch.float64)), scene)
        if projector_gamma is None:
            light = captured_light_to_raw(light, pattern, colour_correction)
    if isinstance(spread_px, torch.Tensor) or spread_px > 0.0:
        light = gaussian_spread(light, spread_px)
    if crosstalk is not None:
        light = torch.einsum(
            "ij,bjhw->bihw", torch.as_tensor(crosstalk, dtype=light.dtype, device=light.device), light
        )
    light = _as(strength, light) * light
    if albedo:
        # a negative floor (the clean frame's veiling glare) returns no light below 0, as the calibration fits it
        light = light * (scene + _as(reflectance_floor, scene)).clamp(min=0.0)
    if blend:
        scene = (1.0 - _as(strength, scene)) * scene
    total = torch.minimum(scene + light, _as(white, scene)).clamp(min=0.0)
    if colour_correction is not None:
        total = mix_channels(colour_correction.to(torch.float64), total).clamp(0.0, 1.0)
    return encode(total, gamma)


def laser_injection(
    x: torch.Tensor,
    light: torch.Tensor,
    power: torch.Tensor,
    *,
    centre: torch.Tensor | None = None,
    color: torch.Tensor | None = None,
    halo_amplitude: float = 0.0,
    halo_exponent: float = 2.0,
    halo_scale_px: float = 1.0,
    measured: torch.Tensor | None = None,
    dark_radius_px: float = 0.0,
    auto_exposure: float = 0.0,
    meter_power: float = 0.0,
    meter_reads: str = "channel_mean",
    gamma: Tone = None,
    colour_correction: torch.Tensor | None = None,
) -> torch.Tensor:
    """A laser shone into the camera, physically: ``light``, the laser's linear light per unit power (``(B or 1,
    3, H, W)``, in the tone curve ``gamma`` decodes: a recorded pattern decoded, a capture's reading from
    ``capture.py``), scaled by ``power`` (per sample), plus an optional power-law glare around ``centre`` (``(B,
    2)`` pixel (x, y)) in the laser's ``color``; the sum adds to the scene in linear light, the auto-exposure
    (``auto_exposure``: a divisor metering the laser's light without its glare; ``meter_power``: a meter of the
    frame's clipped light, :func:`inject_linear_light`) reacts, and the sensor clips before the tone curve (and
    before ``colour_correction``, a camera's (3, 3) matrix, mixes its raw channels: ``light`` and the colour are
    then raw light). ``measured`` (broadcastable ``(H, W)`` bool): where ``light`` is a capture's measurement of
    the laser, which holds the glare already, scaled with the beam, less the glare its dark level took out (the
    glare at ``dark_radius_px`` from the spot, added back there); elsewhere the capture's continued beam and the
    glare estimate one light, and the larger counts (the calibration's frame model composes alike). Without it the
    glare adds everywhere (a procedural pattern holds none)."""
    height, width = x.shape[-2:]
    power = torch.as_tensor(power, dtype=x.dtype, device=x.device).reshape(-1, 1, 1, 1)
    light = power * light.to(x.dtype)
    metered = light
    if halo_amplitude > 0.0:
        if centre is None or color is None:
            raise ValueError("a halo needs the spot centre and the laser colour")
        radius = radial_distance(height, width, centre, dtype=x.dtype, device=x.device)
        shade = power * color.to(x.dtype).reshape(1, 3, 1, 1)
        if measured is None:
            light = light + shade * power_law_halo(radius, halo_amplitude, halo_exponent, halo_scale_px)
        else:
            far = radius.new_tensor(dark_radius_px)
            glare = shade * power_law_halo(
                torch.where(measured, far, radius), halo_amplitude, halo_exponent, halo_scale_px
            )
            light = torch.where(measured, light + glare, torch.maximum(light, glare))
    return inject_linear_light(
        x,
        light,
        auto_exposure=auto_exposure,
        metered_light=metered if meter_power == 0.0 else None,
        meter_power=meter_power,
        meter_reads=meter_reads,
        gamma=gamma,
        colour_correction=colour_correction,
    )


# ---------------------------------------------------------------------------------------------------------------
# rolling shutter (laser color strip)


def cumulative_on_time(t: torch.Tensor, period_s: torch.Tensor, on_s: torch.Tensor) -> torch.Tensor:
    """Total time a pulse train (on for ``on_s`` at the start of every ``period_s``) has been on in [0, t]."""
    cycles = torch.floor(t / period_s)
    return cycles * on_s + torch.minimum(t - cycles * period_s, on_s)


def rolling_shutter_row_light(
    height: int,
    frequency_hz: float | torch.Tensor,
    duty: float | torch.Tensor,
    exposure_s: float | torch.Tensor,
    row_time_s: float | torch.Tensor,
    *,
    integration_offset_s: float | torch.Tensor = 0.0,
    phase_s: float | torch.Tensor = 0.0,
    dtype=torch.float32,
    device=None,
) -> torch.Tensor:
    """Per-row fraction of full brightness a pulsed laser leaves in a rolling-shutter frame -> ``(B, H)``.

    Row ``r`` integrates light during ``[r * row_time + phase, ... + exposure + integration_offset]``; the laser is
    on for ``duty / frequency`` of every period. Rows whose window overlaps a pulse are lit, partially at the
    edges (a ramp), and several stripes appear when the laser period is shorter than the frame readout.
    """
    rows = torch.arange(height, dtype=dtype, device=device).reshape(1, height)

    def col(v):
        return torch.as_tensor(v, dtype=dtype, device=device).reshape(-1, 1)

    period = 1.0 / col(frequency_hz)
    on = col(duty).clamp(0.0, 1.0) * period
    window = (col(exposure_s) + col(integration_offset_s)).clamp(min=1e-9)
    start = rows * col(row_time_s) + col(phase_s)
    lit = cumulative_on_time(start + window, period, on) - cumulative_on_time(start, period, on)
    return (lit / torch.minimum(on, window).clamp(min=1e-12)).clamp(0.0, 1.0)


STRIPE_FRAME_RULES = ("all", "lit", "interior")


def pulse_overlap_lit_time(
    period_s: torch.Tensor,
    on_s: torch.Tensor,
    window_s: torch.Tensor,
    threshold_s: float | torch.Tensor = 0.0,
    noise_s: float | torch.Tensor | None = None,
) -> torch.Tensor:
    """Length of the set of row start times, within one laser period, whose exposure collects more than
    ``threshold_s`` seconds of pulse -> same shape as the inputs (broadcast).

    A row starting at ``t`` integrates ``L(t) = on-time of the pulse train inside [t, t + window]``. ``L`` is
    periodic and piecewise linear with kinks where a window edge meets a pulse edge (``t = 0, on, -window,
    on - window`` modulo the period), so the time above the threshold is exact segment by segment. Threshold 0
    gives ``on + window`` (capped at the period): the pulse/exposure overlap; a threshold shortens it by twice
    the threshold while it is below ``min(on, window)`` (the partly lit rows at both edges of a stripe are not
    counted) and nothing is lit once it exceeds the most a window can collect. With ``noise_s`` (the sensor's
    read noise in seconds of laser light) the threshold is soft: the expected time a row reads above it.
    """
    period, on, window, threshold = torch.broadcast_tensors(
        *(
            torch.as_tensor(v, dtype=torch.float64) if not torch.is_tensor(v) else v
            for v in (period_s, on_s, window_s, threshold_s)
        )
    )
    zero = torch.zeros_like(period)
    kinks = torch.stack([zero, on, -window, on - window], dim=-1)
    kinks = torch.remainder(kinks, period.unsqueeze(-1))
    knots = torch.cat([zero.unsqueeze(-1), torch.sort(kinks, dim=-1).values, period.unsqueeze(-1)], dim=-1)
    light = cumulative_on_time(knots + window.unsqueeze(-1), period.unsqueeze(-1), on.unsqueeze(-1))
    light = light - cumulative_on_time(knots, period.unsqueeze(-1), on.unsqueeze(-1))
    lengths = knots[..., 1:] - knots[..., :-1]
    if noise_s is None:
        high = torch.maximum(light[..., 1:], light[..., :-1])
        low = torch.minimum(light[..., 1:], light[..., :-1])
        above = high - threshold.unsqueeze(-1)
        # a flat piece (a plateau: the window holds the whole pulse) is lit or not as a whole: a step in the
        # threshold whose derivative is 0, not the 1/(high - low) of a slope of no width (seen: a Jacobian column
        # of 5e11 that froze a fit's threshold where it equalled a pulse's on-time). A dark piece is never lit: its
        # light is 0 only up to rounding (seen: 6.9e-18 s at 24.3 Hz, 2% duty, a 281 us window, which with no
        # threshold lit the whole period, 600 rows for 32)
        tolerance = 1e-9 * period.unsqueeze(-1)
        flat = (high - low) <= tolerance
        sloped = (above / (high - low).clamp(min=1e-15)).clamp(0.0, 1.0)
        share = torch.where(flat, ((above > 0) & (high > tolerance)).to(light.dtype), sloped)
        return (share * lengths).sum(-1)
    # read noise: a row is lit with probability Phi((L - threshold) / noise); along a linear piece of L the
    # integral of Phi(z) is G(z) = z Phi(z) + phi(z) over the slope
    noise = torch.as_tensor(noise_s, dtype=light.dtype).clamp(min=1e-15).unsqueeze(-1)
    z = (light - threshold.unsqueeze(-1)) / noise
    z0, z1 = z[..., :-1], z[..., 1:]

    def antiderivative(v):
        return v * torch.special.ndtr(v) + torch.exp(-0.5 * v * v) / math.sqrt(2.0 * math.pi)

    flat = (z1 - z0).abs() < 1e-6
    slope = torch.where(flat, torch.ones_like(z0), z1 - z0)
    share = torch.where(
        flat, torch.special.ndtr(0.5 * (z0 + z1)), (antiderivative(z1) - antiderivative(z0)) / slope
    )
    return (share * lengths).sum(-1)


def rolling_shutter_rows_lit(
    frequency_hz: torch.Tensor,
    duty: torch.Tensor,
    exposure_s: torch.Tensor,
    row_time_s: float | torch.Tensor,
    *,
    image_rows: int | torch.Tensor,
    integration_offset_s: float | torch.Tensor = 0.0,
    threshold_s: float | torch.Tensor = 0.0,
    spread_rows: float | torch.Tensor = 0.0,
    noise_s: float | torch.Tensor | None = None,
    frames: str = "lit",
    drift: float | torch.Tensor | None = None,
    drift_start: str = "placement",
    recording_frames: int | torch.Tensor | None = None,
) -> torch.Tensor:
    """Mean number of rows a pulsed laser lights per counted frame, over a uniformly random pulse phase.

    Terms (each a camera or measurement property; the laser sets ``frequency_hz`` and ``duty``):

    - readout: row ``r`` starts exposing ``r * row_time_s`` after row 0 (rolling shutter), so one period of the
      laser spans ``1 / (frequency * row_time)`` rows and a frame of ``image_rows`` rows sees
      ``image_rows * row_time * frequency`` periods (several stripes when the laser is faster than the readout).
    - exposure window: each row integrates for ``exposure + integration_offset_s`` (the sensor's true
      integration time differs from the nominal setting by a constant).
    - pulse width vs exposure: a row is lit when the pulse train's on-time inside its window exceeds
      ``threshold_s`` (the detection threshold, as seconds of laser light; ``pulse_overlap_lit_time``), so one
      stripe covers ``on + window - 2 threshold`` of start time while the threshold is below the shorter of the
      two; rows at the stripe's edges, lit only in part, drop out first. Read noise (``noise_s``, seconds of
      laser light) makes that detection probabilistic near the threshold (a soft threshold).
    - edge spread: blooming and the optics' glare widen every stripe that lights a row by ``spread_rows`` at each
      edge; a stripe narrower than a row time (``lit < row_time``) lights a row only for ``lit / row_time`` of
      pulse phases, so it adds ``2 spread_rows min(lit, row_time)`` of start time; it never turns a frame in
      which no row reaches the threshold into a lit one.
    - phase and aliasing: the pulse phase relative to the frame is unknowable per frame (it drifts when the laser
      and frame rates beat), so the prediction is the expectation over a uniform phase. Which frames the
      measurement averaged over matters at low frequency, where many frames catch no pulse:
      ``frames="all"`` every frame (``rows * lit share``); ``"lit"`` frames with at least one lit row (a frame
      catches a pulse with probability ``((rows - 1) min(lit, row_time) + lit) / period``, capped at 1);
      ``"interior"`` only frames whose first and last rows are dark (cameras with dead lines: every stripe fully
      visible; the count is the stripe width times the mean number of whole stripes that fit; where the parameters
      leave no whole-stripe placement though a stripe fits, the placement nearest to one stands for them:
      ``_nearest_closed_placement``). The last row starts H - 1 row times after the first, and blooming reaches
      an edge row from inside the frame only.
    - phase drift within a recording (``drift``, per condition, a share of the laser period; ``"interior"`` only):
      a laser whose frequency is close to a multiple of the frame rate beats with it slowly, so one recording
      does not see a random phase per frame: its stripes start where they were placed whole in view and the phase
      advances steadily by ``drift`` of a period over the recording, and frames with a lit row count. Wide
      stripes are then cut by the frame's edges in part of the frames. ``drift=0`` is the interior rule above
      (a locked phase), ``drift=1`` the ``"lit"`` rule (the phase covers the period); with ``drift`` given, the
      average over the placement and the arc is taken on a grid (``_drifting_interior_rows``), also at 0.
      ``drift_start`` says where a drifting recording starts: ``"placement"`` at any whole-stripe placement
      (uniform), ``"entry"`` at the first frame of a run of whole-stripe frames as the stripes move (a recording
      started once its stripes came whole into view): the stripes then cross the frame's whole free span before an
      edge cuts them, so a drift shorter than that span cuts nothing.
    - recording length (``recording_frames``, per condition): a table row is one recording's mean over its lit
      frames, a ratio of two sums over ``N`` frames (frame ``k`` advanced by ``k drift / N``). Its expectation
      exceeds the ratio of the arc's integrals (``None``, a long recording) by a term of order ``1 / N``: the lit
      frames' count and their rows vary together with where the recording starts. On a drift-test draw whose
      wide stripes leave the frame, 24 frames read 2.1% more rows than the long-recording limit and 96 frames
      0.6% (docs/bench/session39.md).
    """
    if frames not in STRIPE_FRAME_RULES:
        raise ValueError(f"unknown frame rule {frames!r}; valid: {', '.join(STRIPE_FRAME_RULES)}")
    if drift_start not in DRIFT_STARTS:
        raise ValueError(f"unknown drift start {drift_start!r}; valid: {', '.join(DRIFT_STARTS)}")
    frequency_hz = torch.as_tensor(frequency_hz, dtype=torch.float64)
    period = 1.0 / frequency_hz
    on = torch.as_tensor(duty, dtype=torch.float64).clamp(0.0, 1.0) * period
    window = (torch.as_tensor(exposure_s, dtype=torch.float64) + integration_offset_s).clamp(min=0.0)
    row_time = torch.as_tensor(row_time_s, dtype=torch.float64)
    height = torch.as_tensor(image_rows, dtype=torch.float64)
    reached = pulse_overlap_lit_time(period, on, window, threshold_s, noise_s)
    # blooming widens stripes that light a row; it lights nothing where no row reaches the threshold, and a
    # stripe narrower than a row time lights a row only for that share of pulse phases
    spread = 2.0 * spread_rows * torch.minimum(reached, row_time)
    lit_time = (reached + spread).clamp(max=period)
    share = lit_time / period
    if frames == "all":
        return height * share
    # blooming cannot light a frame no row of which reaches the threshold
    catch = ((height - 1.0) * torch.minimum(reached, row_time) + reached) / period
    lit_frames = height * share / catch.clamp(min=1e-12, max=1.0)
    lit_frames = torch.where(lit_time > 0, lit_frames, torch.zeros_like(lit_frames))
    if frames == "lit":
        return lit_frames
    p, w = period / row_time, lit_time / row_time
    # an edge row is dark when no stripe reaches it: a stripe blooms into it from inside the frame only (there is no
    # row beyond the edge to bloom from), and the last row starts H - 1 row times after the first
    bloom = 0.5 * spread / row_time
    edge_span = height - 1.0 - bloom
    placements = _interior_placements(p, w - bloom, edge_span)
    total = sum(length for _, _, length in placements)
    closed, nearest = _nearest_closed_placement(p, w - bloom, edge_span)
    possible = ((total > 0) | closed) & (w < p)
    if drift is not None:
        # a recording of a closed set starts at the placement that stands for it
        (lowest, stripes, length), rest = placements[0], placements[1:]
        placements = [
            (
                torch.where(closed, nearest, lowest),
                stripes,
                torch.where(closed, torch.full_like(length, POINT_PLACEMENT), length),
            ),
            *rest,
        ]
        drift = torch.as_tensor(drift, dtype=torch.float64)
        interior = _drifting_interior_rows(
            p,
            w,
            height,
            edge_span,
            placements,
            drift,
            drift_start=drift_start,
            recording_frames=recording_frames,
        )
    else:
        weighted = sum(length * stripes for _, stripes, length in placements)
        start = edge_span - nearest
        nearly_whole = cumulative_on_time(height - start, p, w) - cumulative_on_time(-start, p, w)
        interior = torch.where(closed, nearly_whole, w * weighted / total.clamp(min=1e-12))
    return torch.where(possible, interior, lit_frames)


def _interior_placements(
    p: torch.Tensor, w: torch.Tensor, height: torch.Tensor
) -> list[tuple[torch.Tensor, torch.Tensor, torch.Tensor]]:
    """Where the stripes of a frame with dark first and last rows can lie, in rows (period ``p``, stripe width
    ``w`` as the edge rows see it, the last row ``height`` rows after the first): ``(lowest c', whole stripes,
    length)`` of each interval of ``c' = height - c``, where ``c``, the first stripe's start, is uniform on
    (0, p - w] given row 0 dark; the last row is dark when ``c' mod p >= w``, and then ``ceil(c' / p)`` stripes
    fit."""
    first = torch.floor((height - p + w) / p)
    out = []
    for j in (first, first + 1.0):
        start, stop = _placement_set(p, w, height, j)
        out.append((start, j + 1.0, (stop - start).clamp(min=0.0)))
    return out


def _placement_set(
    p: torch.Tensor, w: torch.Tensor, height: torch.Tensor, j: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """The ends of the ``j``-th set of ``c'`` that shows ``j + 1`` whole stripes (``_interior_placements``); the
    set is empty where ``start >= stop``."""
    start = torch.maximum(torch.maximum(j * p + w, height - p + w), torch.zeros_like(p))
    return start, torch.minimum((j + 1.0) * p, height)


def _nearest_closed_placement(
    p: torch.Tensor, w: torch.Tensor, height: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """``(closed, c')``: whether no placement shows whole stripes (every set of ``_interior_placements`` empty,
    though a stripe fits in the frame), and the placement nearest to doing so, the middle of the set that misses
    by the least.

    A measured row proves that whole-stripe frames occurred, so where the parameters close every set (at a knife
    edge, by a fraction of a row: 7 of 400 simulated frames kept) the frames nearest to whole stand for them: the
    count is then continuous with the open side's (it is that side's limit as the set closes) instead of jumping
    to the lit rule. Seen on drawn camera 1222484455 (interior): at 59.9 Hz and 50% one stripe of 233 rows in a
    418-row period, 233 rows measured; the fitted row time (0.9% long) closed the set and the lit rule predicted
    335. A set of no stripe, or a stripe wider than the frame, stands for nothing: no frame shows it whole."""
    first = torch.floor((height - p + w) / p)
    misses, middles = [], []
    # the set below the first holds no placement (it ends at first * p <= height - p + w) but may be the nearest
    for j in (first - 1.0, first, first + 1.0):
        start, stop = _placement_set(p, w, height, j)
        misses.append(torch.where(j >= 0.0, start - stop, torch.full_like(start, torch.inf)))
        middles.append(0.5 * (start + stop))
    misses, middles = torch.stack(misses), torch.stack(middles)
    least = misses.min(dim=0)
    closed = (least.values >= 0.0) & torch.isfinite(least.values) & (w <= height)
    return closed, middles.gather(0, least.indices.unsqueeze(0)).squeeze(0)


# rows: the weight of the placement that stands for a closed set (only its count matters)
POINT_PLACEMENT = 1e-12


DRIFT_PLACEMENTS = 16  # grid points per interval of whole-stripe placements
DRIFT_STEPS = 64  # grid points along the drift arc of a long recording (recording_frames=None)
DRIFT_STARTS = ("placement", "entry")


def _drifting_interior_rows(
    p: torch.Tensor,
    w: torch.Tensor,
    height: torch.Tensor,
    edge_span: torch.Tensor,
    placements: list[tuple[torch.Tensor, torch.Tensor, torch.Tensor]],
    drift: torch.Tensor,
    drift_start: str = "placement",
    recording_frames: int | torch.Tensor | None = None,
) -> torch.Tensor:
    """Mean over recordings of a recording's mean lit rows over its frames with a lit row, when each recording
    starts from a whole-stripe placement (``_interior_placements`` over ``edge_span``, uniform; a placement's
    ``c = edge_span - c'`` is where its first stripe, bloom included, starts) and its phase then advances steadily
    by ``drift`` of a period (midpoint grids over both; the direction does not matter: the placements and the
    count are symmetric under flipping the frame). A frame whose stripes start at ``s`` lights ``C(H - s) - C(-s)``
    rows, ``C(y)`` the lit length of ``[0, y)`` under stripes of width ``w`` every ``p`` rows
    (``cumulative_on_time``). With ``drift_start="entry"`` each interval of placements contributes only its end the
    stripes move away from (the frame's stripes just whole, a row inside; ``s`` grows, so the stripes move
    down), weighted by the interval's length as before. ``recording_frames`` (``N``, per condition) takes the arc
    at a recording's own frames, ``k / N`` of the drift for ``k = 0 .. N - 1``; ``None`` at the midpoints of
    ``DRIFT_STEPS`` (the limit of a long recording)."""
    grid = (torch.arange(DRIFT_PLACEMENTS, dtype=p.dtype) + 0.5) / DRIFT_PLACEMENTS
    starts, weights = [], []
    for lowest, _, length in placements:
        if drift_start == "entry":
            # a row inside the run: the placements end where the last row starts (H - 1 rows after the first) but a
            # frame counts H rows, so at the run's very end a neighbouring stripe still lights a row (seen on the
            # Logitech table, several stripes per period: any drift > 0 then moved every prediction a row)
            inside = torch.minimum(0.5 * length, torch.ones_like(length))
            c_prime = (lowest + length - inside).unsqueeze(-1)
            weight = length.unsqueeze(-1)
        else:
            c_prime = lowest.unsqueeze(-1) + length.unsqueeze(-1) * grid
            weight = (length / DRIFT_PLACEMENTS).unsqueeze(-1).expand_as(c_prime)
        starts.append(edge_span.unsqueeze(-1) - c_prime)
        weights.append(weight)
    start, weight = torch.cat(starts, -1), torch.cat(weights, -1)
    if recording_frames is None:
        arc = (torch.arange(DRIFT_STEPS, dtype=p.dtype) + 0.5) / DRIFT_STEPS
        in_recording = torch.ones_like(arc)
    else:
        n = torch.as_tensor(recording_frames, dtype=p.dtype)
        if not (torch.isfinite(n).all() and (n >= 1).all() and (n == torch.round(n)).all()):
            raise ValueError(f"recording_frames must be whole numbers >= 1, got {recording_frames}")
        k = torch.arange(int(n.max()), dtype=p.dtype)
        n = n.unsqueeze(-1).unsqueeze(-1)
        # rows of shorter recordings pad their arc past their last frame; those steps count for nothing
        arc, in_recording = k / n, (k < n).to(p.dtype)
    p3, w3 = p.unsqueeze(-1).unsqueeze(-1), w.unsqueeze(-1).unsqueeze(-1)
    s = start.unsqueeze(-1) + (drift * p).unsqueeze(-1).unsqueeze(-1) * arc
    rows = cumulative_on_time(height - s, p3, w3) - cumulative_on_time(-s, p3, w3)
    # a table row is one recording's mean over its lit frames (its first frame is lit: whole stripes in view)
    lit = (rows > 1e-9).to(rows.dtype) * in_recording
    recording = (rows * lit).sum(-1) / lit.sum(-1).clamp(min=1.0)
    return (recording * weight).sum(-1) / weight.sum(-1).clamp(min=1e-300)


# ---------------------------------------------------------------------------------------------------------------
# motion blur (ultrasound on the gyroscope)

BLUR_PATHS = ("uniform", "sinusoidal")


def blur_path_offsets(path: str, taps: int, *, dtype=torch.float32, device=None) -> torch.Tensor:
    """Positions in [-1/2, 1/2] along the blur segment, one per tap, each sample equally weighted.

    ``uniform``: constant velocity (the paper's line average). ``sinusoidal``: a resonating gyroscope moves the
    image as ``sin(w t)``, so equal time steps put more samples near the turning points (arcsine density).
    """
    if path not in BLUR_PATHS:
        raise ValueError(f"unknown blur path {path!r}; valid: {', '.join(BLUR_PATHS)}")
    if taps < 1:
        raise ValueError(f"taps must be >= 1, got {taps}")
    u = (torch.arange(taps, dtype=dtype, device=device) + 0.5) / taps
    if path == "uniform":
        return u - 0.5
    return 0.5 * torch.sin(math.pi * (u - 0.5))


def attack_blur_offsets(path: str, taps: int, *, dtype=torch.float32, device=None) -> torch.Tensor:
    """Shares of an ultrasound blur's displacement its samples sit at: the paper's constant-speed sweep runs one way,
    from the pixel to the full displacement (``uniform``: [0, 1], as the paper's path ``n = i / N``); a resonance
    oscillates about the rest position (``sinusoidal``: centred, :func:`blur_path_offsets`)."""
    offsets = blur_path_offsets(path, taps, dtype=dtype, device=device)
    return offsets + 0.5 if path == "uniform" else offsets


def line_blur(x: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor, offsets: torch.Tensor) -> torch.Tensor:
    """Average of ``x`` shifted by ``offsets * (dx, dy)`` pixels (bilinear, border-replicated), per sample.

    Each tap is a bilinear sample: four whole-pixel neighbours, weighted. The taps of one path share most of their
    neighbours (they sit at most half a pixel apart), so the path is a sparse kernel of whole-pixel shifts, about
    three per pixel of path length, summed over slices of the border-replicated image: one multiply-add per kernel
    entry instead of a ``grid_sample`` per tap (the same sum to rounding; tests/transforms/test_physics.py keeps
    the per-tap form as the reference). Samples that share a displacement share their kernel. Differentiable in
    ``x``; the shifts are read as numbers (the fits difference them numerically).
    """
    batch, _, height, width = x.shape
    shifts = torch.stack(
        [torch.as_tensor(v, dtype=torch.float64).reshape(-1).expand(batch) for v in (dx, dy)], dim=1
    )
    if any(torch.is_tensor(v) and v.requires_grad for v in (dx, dy)):
        raise ValueError("line_blur is not differentiable in dx, dy: pass them without requires_grad")
    path = offsets.detach().to(device="cpu", dtype=torch.float64)
    out = torch.empty_like(x)
    groups: dict[tuple[float, float], list[int]] = {}
    for i, key in enumerate(map(tuple, shifts.tolist())):
        groups.setdefault(key, []).append(i)
    for (shift_x, shift_y), members in groups.items():
        rows, cols, weights = _line_kernel(path, shift_x, shift_y)
        top, left = max(0, -min(rows)), max(0, -min(cols))
        bottom, right = max(0, max(rows)), max(0, max(cols))
        padded_width = left + width + right
        # each pixel's samples are its own position in the padded image moved by row * padded_width + col: on the
        # flattened image every kernel entry is one contiguous slice, summed over the span from the first pixel
        # to the last (the padding columns between rows are summed too and dropped)
        first = top * padded_width + left
        span = (height - 1) * padded_width + width
        for i in members:  # one image at a time: its padded copy and running sum stay in cache
            flat = F.pad(x[i : i + 1], (left, right, top, bottom), mode="replicate").flatten(2)
            total = flat.new_zeros(*flat.shape[:2], height * padded_width)
            running = total[:, :, :span]
            for row, col, weight in zip(rows, cols, weights, strict=True):
                begin = first + row * padded_width + col
                running.add_(flat[:, :, begin : begin + span], alpha=weight)
            out[i].copy_(total.unflatten(2, (height, padded_width))[0, :, :, :width])
    return out


def _line_kernel(
    path: torch.Tensor, shift_x: float, shift_y: float
) -> tuple[list[int], list[int], list[float]]:
    """The whole-pixel shifts ``(rows, cols)`` and weights whose sum is the mean of bilinear samples at
    ``path * (shift_x, shift_y)``: each tap's four neighbours, merged where taps share one, zero weights dropped."""
    px, py = path * shift_x, path * shift_y
    fx, fy = px.floor(), py.floor()
    wx, wy = px - fx, py - fy
    cols = torch.cat([fx, fx + 1, fx, fx + 1]).long()
    rows = torch.cat([fy, fy, fy + 1, fy + 1]).long()
    weights = torch.cat([(1 - wx) * (1 - wy), wx * (1 - wy), (1 - wx) * wy, wx * wy]) / len(path)
    keep = weights > 0
    rows, cols, weights = rows[keep], cols[keep], weights[keep]
    row0, col0 = int(rows.min()), int(cols.min())
    span = int(cols.max()) - col0 + 1
    flat = (rows - row0) * span + (cols - col0)
    kernel = torch.zeros((int(rows.max()) - row0 + 1) * span, dtype=torch.float64).index_add_(
        0, flat, weights
    )
    entries = kernel.nonzero().flatten()
    return (
        (entries // span + row0).tolist(),
        (entries % span + col0).tolist(),
        kernel[entries].tolist(),
    )


def blur_taps(dx: float, dy: float) -> int:
    """Enough taps that neighbouring samples are at most half a pixel apart."""
    return max(3, math.ceil(2.0 * math.hypot(dx, dy)) + 1)


# ---------------------------------------------------------------------------------------------------------------
# EM interference on the video link (EM color strip)


def em_color_map(
    x: torch.Tensor, gain: float | torch.Tensor = 2.5, offset: float | torch.Tensor = 50.0 / 255.0
) -> torch.Tensor:
    """The colour a mis-decoded row shows: R' = B' = gain * G, G' = (R + B) / 2 - offset (the paper's form).

    It is what demosaicing does when the colour-filter phase is off by one: green samples are read as red/blue
    and red/blue samples as green.
    """
    red, green, blue = x[:, 0:1], x[:, 1:2], x[:, 2:3]
    swapped = _as(gain, green) * green
    mixed = 0.5 * (red + blue) - _as(offset, green)
    return torch.cat([swapped, mixed, swapped], dim=1).clamp(0.0, 1.0)


# colour of each site of a 2x2 colour-filter tile, row by row (0 red, 1 green, 2 blue), by its usual name
BAYER_PATTERNS: dict[str, tuple[tuple[int, int], tuple[int, int]]] = {
    "RGGB": ((0, 1), (1, 2)),
    "GRBG": ((1, 0), (2, 1)),
    "GBRG": ((1, 2), (0, 1)),
    "BGGR": ((2, 1), (1, 0)),
}
# bilinear interpolation weights: red and blue sites lie on a square lattice of pitch 2, green on a quincunx
_BILINEAR_RED_BLUE = ((1.0, 2.0, 1.0), (2.0, 4.0, 2.0), (1.0, 2.0, 1.0))
_BILINEAR_GREEN = ((0.0, 1.0, 0.0), (1.0, 4.0, 1.0), (0.0, 1.0, 0.0))


def bayer_line_terms(x: torch.Tensor, pattern: str = "RGGB") -> tuple[torch.Tensor, torch.Tensor]:
    """Each row's bilinear demosaic of ``x``'s mosaic split by the raw line it reads: ``(terms, weights)``.

    The sensor samples one colour per site (``pattern``, the colour-filter tile); a line lost on the bus moves every
    later raw line up by one, so each site holds the sample of the site below it, which sits under another filter
    (a red site holds a green sample, a green site between reds a blue one); the ISP, not knowing, fills in each
    channel by bilinear interpolation of the sites it believes carry that colour (normalised convolution, borders
    mirrored, which keeps the tile's phase). The interpolation is linear in the raw lines, so a row's demosaic is
    the sum of three terms, from the line above, its own and the line below, each either as sampled or moved up by
    one: ``terms[moved, offset]`` ``(2, 3, B, 3, H, W)``, divided by ``weights`` ``(1, 3, H, W)`` (the sum of the
    interpolation weights). The mosaic is read from the frame's own values, the ISP's output (GlitchHiker, Jiang et
    al. 2023; paper, Method). The last raw line is read twice when moved (nothing arrives after it).
    """
    if pattern not in BAYER_PATTERNS:
        raise ValueError(f"unknown colour-filter pattern {pattern!r}; valid: {', '.join(BAYER_PATTERNS)}")
    _, _, height, width = x.shape
    tile = torch.tensor(BAYER_PATTERNS[pattern], device=x.device)
    sites = tile[torch.arange(height, device=x.device) % 2][:, torch.arange(width, device=x.device) % 2]
    raw = x.gather(1, sites.expand(x.shape[0], 1, height, width))
    moved_up = raw[:, :, torch.clamp(torch.arange(height, device=x.device) + 1, max=height - 1)]
    masks = torch.stack([sites == c for c in range(3)]).to(x.dtype).unsqueeze(0)  # (1, 3, H, W)
    kernels = torch.tensor(
        (_BILINEAR_RED_BLUE, _BILINEAR_GREEN, _BILINEAR_RED_BLUE), dtype=x.dtype, device=x.device
    ).unsqueeze(1)
    # one kernel per line offset: row k of the 3x3 kernel alone
    by_offset = [
        kernels * (torch.arange(3, device=x.device) == k).to(x.dtype).reshape(1, 1, 3, 1) for k in range(3)
    ]
    terms = torch.stack(
        [
            torch.stack(
                [F.conv2d(F.pad(lines * masks, (1, 1, 1, 1), mode="reflect"), k, groups=3) for k in by_offset]
            )
            for lines in (raw, moved_up)
        ]
    )
    weights = F.conv2d(F.pad(masks, (1, 1, 1, 1), mode="reflect"), kernels, groups=3)
    return terms, weights


def demosaic_of_moved_lines(terms: torch.Tensor, weights: torch.Tensor, moved: torch.Tensor) -> torch.Tensor:
    """The demosaic (``bayer_line_terms``) when each row's raw line is moved up by the share ``moved`` ``(B, H)``
    (1: the line below it arrived in its place; between 0 and 1, a blend of the two frames); the mirrored border
    line above the first row and below the last is row 1's and row H-2's."""
    height = terms.shape[-2]
    padded = F.pad(moved.to(terms.dtype).unsqueeze(1), (1, 1), mode="reflect")[:, 0]
    total = torch.zeros_like(terms[0, 0])
    for offset in range(3):
        share = padded[:, offset : offset + height].reshape(-1, 1, height, 1)
        total = total + torch.lerp(terms[0, offset], terms[1, offset], share)
    return total / weights


def em_demosaic_rows(
    terms: torch.Tensor,
    weights: torch.Tensor,
    x: torch.Tensor,
    moved: torch.Tensor,
    gain: float | torch.Tensor,
    offset: float | torch.Tensor,
) -> torch.Tensor:
    """The frame ``x`` (with ``bayer_line_terms`` ``terms``, ``weights``) after lost lines moved the raw lines of
    the rows ``moved`` ``(B, H)``: those rows show ``em_colours_of_demosaic`` of the demosaic of the moved lines;
    the others keep their colours, plus what their interpolation now reads from a moved neighbouring line (the row
    on each side of a band's edge)."""
    moved = moved.to(x.dtype)
    after = demosaic_of_moved_lines(terms, weights, moved)
    before = demosaic_of_moved_lines(terms, weights, torch.zeros_like(moved))
    mis_decoded = em_colours_of_demosaic(after, gain, offset)
    return torch.lerp(x + after - before, mis_decoded, moved.reshape(*moved.shape[:1], 1, -1, 1)).clamp(
        0.0, 1.0
    )


def em_colours_of_demosaic(
    demosaiced: torch.Tensor, gain: float | torch.Tensor, offset: float | torch.Tensor
) -> torch.Tensor:
    """``em_color_map`` with the demosaic's spatial form: the map's ``gain`` on the red and blue of a demosaic after
    lost lines (``demosaic_of_moved_lines``: interpolated green samples), its ``offset`` off its green (interpolated
    red and blue), clamped to [0, 1]. On a frame of one colour its red and blue are ``em_color_map``'s and its green
    is, averaged over each 2x2 tile: the green sites keep their own red or blue sample, a zipper the per-pixel map
    smooths away."""
    gain_, offset_ = _as(gain, demosaiced[:, :1]), _as(offset, demosaiced[:, :1])
    red, green, blue = demosaiced[:, 0:1], demosaiced[:, 1:2], demosaiced[:, 2:3]
    return torch.cat([gain_ * red, green - offset_, gain_ * blue], dim=1).clamp(0.0, 1.0)


def periodic_band_mask(
    height: int, period_rows: float | torch.Tensor, phase_rows: float | torch.Tensor = 0.0, *, device=None
) -> torch.Tensor:
    """``(B, 1, H, 1)`` mask of the paper's alternating bands: rows in the first half of every period."""
    rows = torch.arange(height, dtype=torch.float32, device=device).reshape(1, 1, height, 1)
    period = torch.as_tensor(period_rows, dtype=torch.float32, device=device).reshape(-1, 1, 1, 1)
    phase = torch.as_tensor(phase_rows, dtype=torch.float32, device=device).reshape(-1, 1, 1, 1)
    return (torch.remainder(rows - phase, period) < 0.5 * period).to(torch.float32)


def bayer_flip_mask(height: int, start_row: torch.Tensor | float, *, device=None) -> torch.Tensor:
    """``(B, 1, H, 1)`` mask of the rows from ``start_row`` to the frame's end.

    An odd number of dropped rows shifts the colour-filter phase for every later row of the frame, so the wrong
    colours run to the bottom instead of alternating in bands.
    """
    rows = torch.arange(height, dtype=torch.float32, device=device).reshape(1, 1, height, 1)
    start = torch.as_tensor(start_row, dtype=torch.float32, device=device).reshape(-1, 1, 1, 1)
    return (rows >= start).to(torch.float32)
