"""Slow, literal per-pixel references of the paper's Appendix A algorithms for the three optical attacks.

Written from the paper's pseudocode (Algorithms "Laser Blinding Attack", "Light Projection Attack", "Laser Color
Strip Attack") with plain numpy loops, on HWC uint8 images as the paper's code uses; no vectorisation on purpose.
Only for parity tests on small images.
"""

from __future__ import annotations

import math

import numpy as np


def laser_blinding_reference(image: np.ndarray, pattern: np.ndarray, alpha: float) -> np.ndarray:
    """``I = clip(I_orig (1 - alpha) + I_laser alpha, 0, 255)``; ``pattern`` HWC in grey levels (same size)."""
    height, width, channels = image.shape
    out = np.zeros((height, width, channels), dtype=np.uint8)
    for i in range(height):
        for j in range(width):
            for k in range(channels):
                value = float(image[i, j, k]) * (1.0 - alpha) + float(pattern[i, j, k]) * alpha
                out[i, j, k] = int(min(max(value, 0.0), 255.0))  # astype(uint8) truncates
    return out


def light_projection_reference(
    image: np.ndarray, watermark_rgba: np.ndarray, transparency: float, x_offset: int, y_offset: int
) -> np.ndarray:
    """Place the watermark at ``((W - w)/2 + x_off, (H - h)/2 + y_off)`` with alpha ``int(a t)`` (PIL compositing)."""
    height, width, _ = image.shape
    wm_height, wm_width, _ = watermark_rgba.shape
    pos_x = (width - wm_width) // 2 + x_offset
    pos_y = (height - wm_height) // 2 + y_offset
    out = image.copy()
    for i in range(wm_height):
        for j in range(wm_width):
            row, col = pos_y + i, pos_x + j
            if not (0 <= row < height and 0 <= col < width):
                continue
            a = int(float(watermark_rgba[i, j, 3]) * transparency)
            for k in range(3):
                value = (float(watermark_rgba[i, j, k]) * a + float(image[row, col, k]) * (255 - a)) / 255.0
                out[row, col, k] = math.floor(value + 0.5)
    return out


def _strip_intensity(p: int, q: int, start: int, strength: float, height: int, width: int) -> float:
    """The paper's intensity function I(p, q) with the code's centre, sigmas and S * h * w scaling (rho = 0)."""
    rho = 0.0
    sigma_p, sigma_q = height / 2, width / 4
    a = (p - start - height / 2) ** 2 / sigma_p**2
    b = (q - width / 2) ** 2 / sigma_q**2
    c = 2 * rho * (p - start - height / 2) * (q - width / 2) / (sigma_p * sigma_q)
    norm = 1 / (2 * math.pi * sigma_p * sigma_q * math.sqrt(1 - rho**2))
    return norm * math.exp(-1 / (2 * (1 - rho**2)) * (a + b - c)) * strength * height * width


def laser_color_strip_reference(
    image: np.ndarray, strength: float, color_fractions: tuple[float, float, float]
) -> np.ndarray:
    """Rows ``h//3 .. (h//3)*2`` get ``+ I(p, q) * fraction`` per channel, clipped, stored as uint8."""
    height, width, _ = image.shape
    row_start, row_end = height // 3, (height // 3) * 2
    work = image.astype(np.float64)
    for i in range(width):
        for j in range(row_start, row_end):
            intensity = _strip_intensity(j, i, row_start, strength, height, width)
            for k in range(3):
                work[j, i, k] = min(max(work[j, i, k] + intensity * color_fractions[k], 0.0), 255.0)
    return work.astype(np.uint8)
