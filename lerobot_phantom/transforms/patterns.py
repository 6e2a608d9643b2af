"""Attack patterns: procedural laser spots and projected shapes, and user pattern images loaded once.

The paper blends *recorded* patterns (a photo of a laser hitting the camera, photos of projected images). This
package ships no third-party images, so the patterns are generated here from a few physical parameters, and a
user may pass the path of their own capture instead. Laser patterns are sized relative to the image (the glare to
the frame, the spot to the shorter side ``L = min(H, W)``), so a 96x96 and a 480x640 camera see the same attack;
projected shapes have a native pixel size (``NATIVE_SHAPE_HEIGHT``), as the authors' watermark has.

Laser spot model (``laser_spot``): the lens spreads a laser beam into a point-spread function with a flat core and
a power-law glare tail, ``E(r) = (1 + (r / r_core)^2)^(-k / 2)`` (``k`` = ``halo_exponent``; veiling glare falls
off roughly as ``r^-2``), optionally plus ``streaks`` diffraction/flare lines through the centre. A colour sensor
sees channel ``c`` with sensitivity ``s_c = crosstalk + (1 - crosstalk) * colour_c`` (Bayer filters leak some
laser light into the other channels) and saturates at 1. The gain is chosen so that the leaking channels saturate
exactly at ``r = r_core``: inside, every channel clips (the white core); further out only the laser-colour channel
clips (the coloured ring); beyond that the halo fades as a power law in the laser colour. This is the ``"spot"``
pattern of ``LaserBlinding`` (a dark frame with a small spot).

Laser glare model (``laser_glare``, the default ``"red"`` pattern of ``LaserBlinding``): what the paper's authors
recorded (their ``red.png``, a red laser shone straight into the lens) is a frame flooded with light, not a spot:
a saturated white core over about a third of the frame, a pink ring where green has fallen off but blue has not,
and a red field to the corners. Each channel follows ``clip(floor + amplitude * exp(-(r / radius)^sharpness))``
with ``r`` the distance from the centre in frame units (rows / H, columns / W, so the glare stretches with the
frame as the authors' capture does when resized to it); ``RED_LASER_GLARE`` holds the per-channel constants, fitted
by least squares to the radial profile of the authors' capture, the G and B floors then shifted so that the mean
colour is theirs, (245, 79, 132); values >= 250: 27.3% vs their 27.0% at 224x224 (the comparison table of the
attacked frames is in the README). Values are quantised to 8 bits like a recorded capture.

Projected shapes (``projection_shape``) are drawn with PIL; ``"can"`` (the default of ``LightProjection``) mimics
the authors' ``can.png`` watermark: 50x42 pixels, a silver can with a red label band and a white lower label with a
red fruit, alpha coverage 0.66, text-free. User images are resized with PIL's LANCZOS filter, as the authors do.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import torch

if TYPE_CHECKING:
    from PIL import ImageDraw

LASER_COLORS: dict[str, tuple[float, float, float]] = {
    "red": (1.0, 0.0, 0.0),  # 650 nm
    "green": (0.0, 1.0, 0.0),  # 532 nm
    "blue": (0.0, 0.0, 1.0),  # 450 nm
    "violet": (0.5, 0.0, 1.0),  # 405 nm: seen by the red and blue filters
    "white": (1.0, 1.0, 1.0),
}

PROJECTION_SHAPES: tuple[str, ...] = ("can", "stop_sign", "arrow", "disk")
"""Procedural projected images (text-free): a food can like the authors' watermark, a red octagon with a white rim,
a yellow arrow and a plain bright disk."""

NATIVE_SHAPE_HEIGHT = 50
"""Native height in pixels of a procedural shape (the authors' ``can.png`` is 50x42): ``LightProjection`` with
``size="native"`` pastes it at this pixel size on every frame, as the authors paste their watermark."""

SHAPE_ASPECT: dict[str, float] = {"can": 42 / 50}
"""Width / height of the procedural shapes that are not square."""


@dataclass(frozen=True)
class GlareChannel:
    """One colour channel of ``laser_glare``: ``clip(floor + amplitude * exp(-(r / radius)^sharpness))``."""

    floor: float
    amplitude: float
    radius: float
    sharpness: float


RED_LASER_GLARE: tuple[GlareChannel, GlareChannel, GlareChannel] = (
    GlareChannel(floor=0.803, amplitude=0.293, radius=0.514, sharpness=3.0),
    GlareChannel(floor=0.0555, amplitude=1.475, radius=0.2726, sharpness=3.92),
    GlareChannel(floor=0.177, amplitude=0.955, radius=0.3634, sharpness=2.98),
)
"""R, G, B of the red laser glare: least-squares fit to the radial profile of the authors' ``red.png``, the G and B
floors lowered by 0.005 and 0.0135 so that the mean colour matches too."""

_SUPERSAMPLE = 4  # shapes are drawn at 4x and downsampled (antialiased edges)


def check_levels(levels: Sequence[float], what: str, upper: float | None = None) -> tuple[float, ...]:
    """Validate a level table (values at s = 0, weak, medium, strong): identity 0 first, non-decreasing."""
    values = tuple(float(v) for v in levels)
    if len(values) != 4 or values[0] != 0.0 or any(b < a for a, b in itertools.pairwise(values)):
        raise ValueError(
            f"{what} levels must be 4 non-decreasing values (identity=0, weak, medium, strong), got {levels!r}"
        )
    if upper is not None and values[-1] > upper:
        raise ValueError(f"{what} levels must not exceed {upper}, got {levels!r}")
    return values


def parse_color(color: str | Sequence[float]) -> tuple[float, float, float]:
    """A laser colour name or an RGB triple (floats in [0, 1] or ints in 0-255) -> RGB with max 1."""
    if isinstance(color, str):
        key = color.strip().lower()
        if key not in LASER_COLORS:
            raise ValueError(
                f"unknown laser colour {color!r}; valid: {', '.join(LASER_COLORS)} or an RGB triple"
            )
        return LASER_COLORS[key]
    values = [float(v) for v in color]
    if len(values) != 3 or any(not math.isfinite(v) or v < 0 for v in values):
        raise ValueError(f"an RGB colour needs three non-negative numbers, got {color!r}")
    if max(values) > 1.0:
        values = [v / 255.0 for v in values]
    peak = max(values)
    if peak <= 0:
        raise ValueError(f"an RGB colour cannot be black, got {color!r}")
    return (values[0] / peak, values[1] / peak, values[2] / peak)


def laser_spot(
    height: int,
    width: int,
    *,
    center: tuple[float, float],
    core_radius: float,
    halo_exponent: float,
    color: tuple[float, float, float],
    crosstalk: float = 0.25,
    streaks: int = 0,
    streak_strength: float = 0.3,
    streak_width: float = 0.01,
    streak_angle: float = 15.0,
    unit: float | None = None,
    device: torch.device | str | None = None,
) -> torch.Tensor:
    """A laser-spot pattern, float32 ``(3, height, width)`` in [0, 1].

    ``center`` = (row, col) in pixels (may be fractional or outside the image); ``core_radius`` and
    ``streak_width`` are fractions of ``unit`` (default ``min(height, width)``); ``streak_angle`` in degrees.
    """
    if core_radius <= 0 or halo_exponent <= 0 or not (0 < crosstalk <= 1):
        raise ValueError(
            f"laser spot needs core_radius > 0, halo_exponent > 0 and crosstalk in (0, 1], got "
            f"{core_radius}, {halo_exponent}, {crosstalk}"
        )
    unit = float(min(height, width) if unit is None else unit)
    rows = (torch.arange(height, dtype=torch.float32, device=device) - center[0]) / unit
    cols = (torch.arange(width, dtype=torch.float32, device=device) - center[1]) / unit
    dy, dx = rows[:, None], cols[None, :]
    radius_sq = dy * dy + dx * dx
    irradiance = (1.0 + radius_sq / core_radius**2) ** (-halo_exponent / 2.0)
    for j in range(streaks):
        theta = math.radians(streak_angle) + j * math.pi / streaks
        along = dx * math.cos(theta) + dy * math.sin(theta)
        across = -dx * math.sin(theta) + dy * math.cos(theta)
        falloff = (1.0 + along * along / core_radius**2) ** (-halo_exponent / 4.0)
        irradiance = irradiance + streak_strength * falloff * torch.exp(-0.5 * (across / streak_width) ** 2)
    gain = 2.0 ** (halo_exponent / 2.0) / crosstalk
    sensitivity = torch.tensor(
        [crosstalk + (1.0 - crosstalk) * c for c in color], dtype=torch.float32, device=device
    )
    return (gain * irradiance[None] * sensitivity[:, None, None]).clamp_(0.0, 1.0)


def laser_glare(
    height: int,
    width: int,
    *,
    center: tuple[float, float] | None = None,
    frame: tuple[int, int] | None = None,
    channels: Sequence[GlareChannel] = RED_LASER_GLARE,
    device: torch.device | str | None = None,
) -> torch.Tensor:
    """A laser glare pattern, float32 ``(3, height, width)`` on the 8-bit grid (see the module docstring).

    ``center`` = (row, col) in pixels (default the middle, ``((height - 1) / 2, (width - 1) / 2)``); distances are
    measured in units of ``frame`` = (H, W) (default ``(height, width)``; a larger canvas passes the frame it is
    cropped for).
    """
    if len(channels) != 3:
        raise ValueError(f"laser glare needs 3 channel profiles (R, G, B), got {len(channels)}")
    for channel in channels:
        if channel.radius <= 0 or channel.sharpness <= 0:
            raise ValueError(f"glare channels need radius > 0 and sharpness > 0, got {channel}")
    frame_h, frame_w = (height, width) if frame is None else frame
    row0, col0 = ((height - 1) / 2.0, (width - 1) / 2.0) if center is None else center
    dy = (torch.arange(height, dtype=torch.float32, device=device) - row0) / frame_h
    dx = (torch.arange(width, dtype=torch.float32, device=device) - col0) / frame_w
    radius = torch.sqrt(dy[:, None] ** 2 + dx[None, :] ** 2)
    planes = [
        (c.floor + c.amplitude * torch.exp(-((radius / c.radius) ** c.sharpness))).clamp_(0.0, 1.0)
        for c in channels
    ]
    return torch.stack(planes).mul_(255.0).round_().div_(255.0)


def load_pattern_image(path: str | Path, *, keep_alpha: bool) -> torch.Tensor:
    """Read a user pattern image once: float32 ``(3, h, w)`` (or ``(4, h, w)`` RGBA when ``keep_alpha``) in [0, 1].

    Images without alpha get an opaque alpha channel when ``keep_alpha`` is set.
    """
    from PIL import Image  # torchvision's own dependency

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"pattern image not found: {path}")
    with Image.open(path) as image:
        image = image.convert("RGBA" if keep_alpha else "RGB")
        data = torch.frombuffer(bytearray(image.tobytes()), dtype=torch.uint8)
        tensor = data.reshape(image.height, image.width, len(image.getbands())).permute(2, 0, 1)
    return tensor.to(torch.float32) / 255.0


def resize_pattern(pattern: torch.Tensor, height: int, width: int) -> torch.Tensor:
    """Resize a ``(C, h, w)`` pattern to ``(C, height, width)`` with PIL's LANCZOS filter, as the authors' code.

    A pattern on the 8-bit grid (``uint8``, or float whose values are multiples of 1/255, as loaded images and
    procedural shapes are) is resized as an 8-bit PIL image (RGB, or RGBA with PIL's premultiplied alpha), so the
    result is bit-exact with the authors' ``Image.resize(..., LANCZOS)``; other float patterns are resized per
    channel in PIL's 32-bit float mode. Returns the input's dtype (float results clipped to [0, 1]).
    """
    from PIL import Image  # torchvision's own dependency

    if pattern.shape[-2:] == (height, width):
        return pattern
    channels = pattern.shape[0]
    device = pattern.device
    as_uint8 = pattern if pattern.dtype == torch.uint8 else None
    if as_uint8 is None:
        scaled = pattern.detach().to("cpu", torch.float32) * 255.0
        if channels in (3, 4) and bool((scaled == scaled.round()).all()):
            as_uint8 = scaled.round().clamp(0, 255).to(torch.uint8)
    if as_uint8 is not None and channels in (3, 4):
        image = Image.fromarray(
            as_uint8.cpu().permute(1, 2, 0).contiguous().numpy(), "RGBA" if channels == 4 else "RGB"
        )
        data = image.resize((width, height), Image.Resampling.LANCZOS)
        out = torch.frombuffer(bytearray(data.tobytes()), dtype=torch.uint8).reshape(height, width, channels)
        out = out.permute(2, 0, 1).contiguous().to(device)
        return out if pattern.dtype == torch.uint8 else out.to(pattern.dtype) / 255.0
    planes = []
    for plane in pattern.detach().to("cpu", torch.float32):
        image = Image.fromarray(plane.contiguous().numpy(), "F").resize(
            (width, height), Image.Resampling.LANCZOS
        )
        planes.append(
            torch.frombuffer(bytearray(image.tobytes()), dtype=torch.float32).reshape(height, width)
        )
    out = torch.stack(planes).to(device)
    if pattern.dtype == torch.uint8:
        return out.round().clamp(0, 255).to(torch.uint8)
    return out.clamp_(0.0, 1.0).to(pattern.dtype)


def exact_float64(pattern: torch.Tensor) -> torch.Tensor:
    """A pattern in float64 with its values on the 8-bit grid exactly ``k / 255``, as the calibration reads an 8-bit
    image (``frame_models.common.load_rgb``). float32's ``k / 255`` widened differs in its last bits, and a capture's
    reading thresholds them (its spot's centre, and the room's gradient read about it: a pixel's flip moved the
    centre 0.14 px, session 96). Values off the grid are widened as they are."""
    wide = pattern.double()
    levels = (wide * 255.0).round()
    return torch.where((wide * 255.0 - levels).abs() < 1e-3, levels / 255.0, wide)


def fit_size(pattern_height: int, pattern_width: int, box: int) -> tuple[int, int]:
    """Size of a pattern scaled so its longer side is ``box`` pixels, aspect kept, at least 1x1."""
    scale = box / max(pattern_height, pattern_width)
    return max(1, round(pattern_height * scale)), max(1, round(pattern_width * scale))


def _regular_polygon(
    cx: float, cy: float, radius: float, sides: int, rotation: float
) -> list[tuple[float, float]]:
    return [
        (
            cx + radius * math.cos(rotation + 2 * math.pi * i / sides),
            cy + radius * math.sin(rotation + 2 * math.pi * i / sides),
        )
        for i in range(sides)
    ]


def projection_shape(name: str, size: int) -> torch.Tensor:
    """A procedural projected image, float32 RGBA ``(4, size, round(size * aspect))`` in [0, 1] on the 8-bit grid.

    ``size`` is the height in pixels; the can is 42/50 as wide as it is tall (``SHAPE_ASPECT``), the others square.
    Drawn with PIL at 4x and downsampled with LANCZOS, so edges are antialiased at every size.
    """
    from PIL import Image, ImageDraw

    if name not in PROJECTION_SHAPES:
        raise ValueError(
            f"unknown projection pattern {name!r}; valid: {', '.join(PROJECTION_SHAPES)} or an image path"
        )
    height = max(1, int(size))
    width = max(1, round(height * SHAPE_ASPECT.get(name, 1.0)))
    n_h, n_w = height * _SUPERSAMPLE, width * _SUPERSAMPLE
    canvas = Image.new("RGBA", (n_w, n_h), (0, 0, 0, 0))
    draw = ImageDraw.Draw(canvas)
    if name == "can":
        _draw_can(draw, n_w, n_h)
    else:
        n = n_h
        c = (n - 1) / 2.0
        if name == "stop_sign":
            octagon = math.pi / 8
            draw.polygon(_regular_polygon(c, c, n * 0.5, 8, octagon), fill=(255, 255, 255, 255))
            draw.polygon(_regular_polygon(c, c, n * 0.44, 8, octagon), fill=(204, 18, 30, 255))
        elif name == "arrow":
            shaft = [(0.05 * n, 0.38 * n), (0.55 * n, 0.38 * n), (0.55 * n, 0.62 * n), (0.05 * n, 0.62 * n)]
            head = [(0.5 * n, 0.12 * n), (0.97 * n, 0.5 * n), (0.5 * n, 0.88 * n)]
            draw.polygon(shaft, fill=(255, 214, 0, 255))
            draw.polygon(head, fill=(255, 214, 0, 255))
        else:  # disk
            draw.ellipse([0, 0, n - 1, n - 1], fill=(255, 255, 255, 255))
    canvas = canvas.resize((width, height), Image.Resampling.LANCZOS)
    data = torch.frombuffer(bytearray(canvas.tobytes()), dtype=torch.uint8).reshape(height, width, 4)
    return data.permute(2, 0, 1).to(torch.float32) / 255.0


def _draw_can(draw: ImageDraw.ImageDraw, width: float, height: float) -> None:
    """A food can seen from the front, in the layout and colours of the authors' ``can.png`` (text-free)."""

    def box(x0: float, y0: float, x1: float, y1: float) -> list[float]:
        return [x0 * width, y0 * height, x1 * width, y1 * height]

    left, right, lid = 0.155, 0.875, 0.12  # body columns and the height of the elliptic rims (fractions)
    silver, red, white = (172, 177, 183, 255), (188, 33, 41, 255), (240, 241, 241, 255)
    draw.ellipse(box(left, 0.84, right, 0.96), fill=(150, 157, 163, 255))  # bottom rim
    draw.rectangle(box(left, 0.03 + lid / 2, right, 0.90), fill=silver)
    draw.ellipse(box(left, 0.03, right, 0.03 + lid), fill=(176, 181, 187, 255))  # lid
    draw.rectangle(box(left, 0.25, right, 0.45), fill=red)  # label band
    draw.rectangle(
        box(left + 0.1, 0.31, right - 0.1, 0.37), fill=(228, 160, 164, 255)
    )  # where the name would be
    draw.rectangle(box(left, 0.45, right, 0.88), fill=white)  # lower label
    draw.ellipse(box(0.27, 0.56, 0.75, 0.83), fill=(204, 40, 46, 255))  # the fruit
    draw.ellipse(box(0.43, 0.53, 0.59, 0.60), fill=(60, 140, 60, 255))  # its leaves
