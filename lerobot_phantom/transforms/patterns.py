"""Attack patterns: procedural laser spots and projected shapes, and user pattern images loaded once.

The paper blends *recorded* patterns (a photo of a laser hitting the camera, photos of projected images). This
package ships no third-party images, so the patterns are generated here from a few physical parameters, and a
user may pass the path of their own capture instead. Every size is relative to the image (the shorter side
``L = min(H, W)``), so a 96x96 and a 480x640 camera see the same attack.

Laser spot model (``laser_spot``): the lens spreads a laser beam into a point-spread function with a flat core and
a power-law glare tail, ``E(r) = (1 + (r / r_core)^2)^(-k / 2)`` (``k`` = ``halo_exponent``; veiling glare falls
off roughly as ``r^-2``), optionally plus ``streaks`` diffraction/flare lines through the centre. A colour sensor
sees channel ``c`` with sensitivity ``s_c = crosstalk + (1 - crosstalk) * colour_c`` (Bayer filters leak some
laser light into the other channels) and saturates at 1. The gain is chosen so that the leaking channels saturate
exactly at ``r = r_core``: inside, every channel clips (the white core); further out only the laser-colour channel
clips (the coloured ring); beyond that the halo fades as a power law in the laser colour.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from pathlib import Path

import torch

LASER_COLORS: dict[str, tuple[float, float, float]] = {
    "red": (1.0, 0.0, 0.0),  # 650 nm
    "green": (0.0, 1.0, 0.0),  # 532 nm
    "blue": (0.0, 0.0, 1.0),  # 450 nm
    "violet": (0.5, 0.0, 1.0),  # 405 nm: seen by the red and blue filters
    "white": (1.0, 1.0, 1.0),
}

PROJECTION_SHAPES: tuple[str, ...] = ("stop_sign", "arrow", "can", "disk")
"""Procedural projected images (text-free): a red octagon with a white rim, a yellow arrow, a soda-can silhouette
and a plain bright disk."""

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
    """Resize a ``(C, h, w)`` float pattern to ``(C, height, width)``; antialiased bicubic (the paper used LANCZOS)."""
    if pattern.shape[-2:] == (height, width):
        return pattern
    resized = torch.nn.functional.interpolate(
        pattern[None], size=(height, width), mode="bicubic", antialias=True, align_corners=False
    )[0]
    return resized.clamp_(0.0, 1.0)


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
    """A procedural projected image, float32 RGBA ``(4, size, size)`` in [0, 1], alpha quantised to 1/255.

    Drawn with PIL at 4x and downsampled with LANCZOS, so edges are antialiased at every size.
    """
    from PIL import Image, ImageDraw

    if name not in PROJECTION_SHAPES:
        raise ValueError(
            f"unknown projection pattern {name!r}; valid: {', '.join(PROJECTION_SHAPES)} or an image path"
        )
    size = max(1, int(size))
    n = size * _SUPERSAMPLE
    canvas = Image.new("RGBA", (n, n), (0, 0, 0, 0))
    draw = ImageDraw.Draw(canvas)
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
    elif name == "can":
        left, right, top, bottom, lid = 0.28 * n, 0.72 * n, 0.06 * n, 0.94 * n, 0.08 * n
        draw.rectangle([left, top + lid / 2, right, bottom - lid / 2], fill=(200, 20, 35, 255))
        draw.ellipse([left, bottom - lid, right, bottom], fill=(200, 20, 35, 255))
        draw.ellipse([left, top, right, top + lid], fill=(205, 205, 210, 255))
        draw.rectangle([left, 0.45 * n, right, 0.55 * n], fill=(245, 245, 245, 255))
    else:  # disk
        draw.ellipse([0, 0, n - 1, n - 1], fill=(255, 255, 255, 255))
    canvas = canvas.resize((size, size), Image.Resampling.LANCZOS)
    data = torch.frombuffer(bytearray(canvas.tobytes()), dtype=torch.uint8).reshape(size, size, 4)
    return data.permute(2, 0, 1).to(torch.float32) / 255.0
