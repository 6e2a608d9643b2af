"""Slow, literal per-pixel references of the paper's Appendix A algorithms for EM color strip, EM truncation and
ultrasound blur (Phantom Menace, AAAI-26, Algorithms "EM Color Strip", "EM Truncation", "Ultrasound Blur").

They work like the paper's released code: on ``(H, W, 3)`` uint8 numpy arrays, one pixel at a time with Python
arithmetic. Each takes a switch that reproduces a defect of the released code (``paper_*=True``) so the tests can
show what the package fixes; with the switch off they are the corrected algorithm the fast transforms implement.
Nothing here is fast or vectorised on purpose: these are the ground truth the fast kernels are checked against.
"""

from __future__ import annotations

import math

import numpy as np

MAX_BLUR_SAMPLES = 100


def _clip_u8(value: float) -> int:
    return int(min(max(value, 0), 255))


def em_color_strip_reference(
    image: np.ndarray, num_stripes: int, *, paper_uint8_sum: bool = False
) -> np.ndarray:
    """Alternate horizontal bands of ``int(h / num_stripes)`` rows get the EMI colour-decoding error.

    ``paper_uint8_sum=True`` adds R and B as uint8 like the released code, which wraps modulo 256.
    ``step`` is at least 1 (the released code crashes on ``range(..., 0)`` when ``h < num_stripes``).
    """
    h, w = image.shape[:2]
    out = image.copy()
    step = max(1, int(h / num_stripes))
    for down in range(0, h - step, 2 * step):
        for y in range(down, down + step):
            for x in range(w):
                r, g, b = image[y, x, 0], image[y, x, 1], image[y, x, 2]
                # the released code adds two np.uint8 values, which wraps modulo 256
                red_plus_blue = (int(r) + int(b)) % 256 if paper_uint8_sum else int(r) + int(b)
                new_r = _clip_u8(int(int(g) * 2.5))
                new_g = _clip_u8(int(red_plus_blue / 2) - 50)
                new_b = _clip_u8(int(int(g) * 2.5))
                out[y, x] = (new_r, new_g, new_b)
    return out


def rows_after_deleting(height: int, num: int, start: int) -> list[int]:
    """The source row of every output row when ``num`` rows from ``start`` are deleted and the last ``num`` rows
    appended (the released code's ``np.delete`` / ``np.append``; a band reaching past the frame deletes fewer rows
    and the output is taller, as there)."""
    kept = [row for row in range(height) if not (start <= row < start + num)]
    return kept + list(range(height - num, height))


def em_truncation_reference(
    image: np.ndarray, ratio: float, *, paper_start: bool = False, start: int | None = None
) -> np.ndarray:
    """Delete ``int(h*r)`` rows starting at ``int(h*r)`` and append the last ``int(h*r)`` rows.

    ``paper_start=True`` keeps the released code's ``start = int(h*r)`` (identity at r = 0.5, taller output above);
    otherwise ``start = max(0, min(int(h*r), h - 2*num))``, or the given ``start`` (a free band).
    """
    h = image.shape[0]
    num = int(h * ratio)
    if start is None:
        start = int(h * ratio) if paper_start else max(0, min(int(h * ratio), h - 2 * num))
    return np.stack([image[row] for row in rows_after_deleting(h, num, start)], axis=0)


def ultrasound_blur_reference(
    image: np.ndarray,
    dx: float,
    dy: float,
    theta_deg: float = 0.0,
    scale: float = 0.0,
    *,
    paper_block2x2: bool = False,
    snap: float = 0.0,
) -> np.ndarray:
    """Each pixel becomes the mean of the in-bounds pixels along its motion path (linear + rotation + radial).

    Arguments are in the paper code's frame, where ``x`` is the row and ``y`` the column: ``dx`` moves along rows
    (vertical), ``dy`` along columns. ``paper_block2x2=True`` reproduces the released code's loop over every second
    pixel that copies the average into a 2x2 block. ``snap`` is added before every ``int()``: 0 is the paper's
    literal float64 arithmetic, in which ``R*cos(alpha) + c0`` lands a few ulp below the integer ``x`` for ~8 % of
    pixels and truncates one pixel short; a tiny ``snap`` (1e-6) gives the exact-arithmetic path the fast kernel
    computes. ``atan2`` replaces ``atan(dy/dx)`` (which divides by zero at ``dx = 0``); identical for ``dx > 0``.
    """
    h, w = image.shape[:2]
    c0, c1 = int(h / 2), int(w / 2)
    delta = math.atan2(dy, dx)
    length = math.hypot(dx, dy)
    theta = theta_deg * math.pi / 180.0
    out = image.copy()
    stride = 2 if paper_block2x2 else 1
    for x in range(0, h, stride):
        for y in range(0, w, stride):
            radius = math.hypot(x - c0, y - c1)
            alpha = math.atan2(y - c1, x - c0)
            x_cos = length * math.cos(delta) - scale * radius * math.cos(alpha)
            y_sin = length * math.sin(delta) - scale * radius * math.sin(alpha)
            end_x = radius * math.cos(alpha + theta) + x_cos + c0 - x
            end_y = radius * math.sin(alpha + theta) + y_sin + c1 - y
            num = min(int(max(abs(end_x), abs(end_y)) + snap), MAX_BLUR_SAMPLES)
            if num <= 0:
                value = image[x, y].astype(np.float64)
            else:
                total = np.zeros(image.shape[2], dtype=np.float64)
                count = 0
                for i in range(num + 1):
                    n = i / num
                    xt = int(radius * math.cos(alpha + n * theta) + n * x_cos + c0 + snap)
                    yt = int(radius * math.sin(alpha + n * theta) + n * y_sin + c1 + snap)
                    if 0 <= xt < h and 0 <= yt < w:
                        total += image[xt, yt]
                        count += 1
                value = total / count if count else image[x, y].astype(np.float64)
            out[x : x + stride, y : y + stride] = value.astype(np.uint8)  # numpy truncates toward zero
    return out
