"""Laser color strip: a switch-modulated laser paints coloured bands through the CMOS rolling shutter
(paper: Method, "Laser Color Strip Attack", after Yan et al., "Rolling colors"; Appendix A, Algorithm
"Laser Color Strip Attack").

Physics: each sensor row is exposed at a slightly different time, so a laser switched on for part of the frame
adds light to a horizontal band only; the laser's wavelength sets how the light splits over the colour channels.
Algorithm (as the paper's code): rows ``h//3 .. (h//3)*2`` (end exclusive) get, at pixel (row p, col q),

    I(p, q) = S * h * w / (2 pi sigma_p sigma_q sqrt(1 - rho^2))
              * exp(-(a + b - c) / (2 (1 - rho^2))),     sigma_p = h/2, sigma_q = w/4, rho = 0,
    a = (p - c_p)^2 / sigma_p^2,  b = (q - c_q)^2 / sigma_q^2,  c = 2 rho (p - c_p)(q - c_q) / (sigma_p sigma_q) = 0,
    c_p = h//3 + h/2,  c_q = w/2,

and channel k gets ``+ I * fraction_k`` (grey levels), clipped to [0, 255]. Note that the code measures ``p``
from the band start plus ``h/2``, so the Gaussian's centre lies *below* the band (at ``h//3 + h/2``) and the band
brightens towards its lower edge; this is kept as in the paper's code. The ``S h w`` factor cancels the Gaussian's
normaliser up to ``4/pi``, so the peak gain ``4 S / pi`` does not depend on the image size.

Levels: Table 2 lists the "weight" 0.5 / 1.5 / 2.5; the code's strength is that weight x 1000, S = 500 / 1500 /
2500 grey-level units (of an 8-bit image; float images are handled as value x 255). S = 0 at s = 0, linear in
between (``interpolate_levels``). Colour fractions (R, G, B) default to the paper's (0.6, 0.1, 0.1) (a red laser).
Nothing else is random: the band is fixed by the image size.

Deviations from the paper's code: vectorised; the (H, W) profile is computed once per (H, W, device) and cached
(the loops recompute it per pixel), and at a fixed level the whole increment too; uint8 images stay uint8 (a
saturating add of the rounded increment), so the output is rounded instead of truncated by ``astype(uint8)``
(at most 1 grey level apart). ``"random"`` draws the authors' adversarial-training strength ``S ~ U(500, 2500)``.

``model="rolling_shutter"`` (fitted by ``lerobot-phantom-calibrate``) replaces the band by the rows a pulsed laser
lights through a rolling shutter (``physics.rolling_shutter_row_light``) at a random pulse phase per sample; with
``gamma`` its light adds in linear irradiance under the power-law tone curve ``x ** gamma`` (with ``shoulder``, a
tone curve whose highlights roll off, ``physics.ShoulderCurve``), so dark surfaces gain more grey levels than bright
ones and the sum saturates at white.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import ClassVar

import torch

from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.base import (
    CameraAttack,
    check_image,
    from_float_rgb,
    from_uint8_rgb,
    to_float_rgb,
    to_rgb,
)
from lerobot_phantom.transforms.intensity import IntensitySpec, RandomParameter, interpolate_levels
from lerobot_phantom.transforms.patterns import check_levels

STRENGTH_LEVELS: tuple[float, float, float, float] = (0.0, 500.0, 1500.0, 2500.0)
PAPER_COLOR_FRACTIONS: tuple[float, float, float] = (0.6, 0.1, 0.1)


def band_rows(height: int) -> tuple[int, int]:
    """The attacked rows ``[start, end)`` of the paper's code."""
    return height // 3, (height // 3) * 2


def strip_profile(height: int, width: int, device: torch.device | str | None = None) -> torch.Tensor:
    """``I(p, q)`` for S = 1 over the band rows, float32 ``(end - start, width)`` in grey levels."""
    start, end = band_rows(height)
    rho = 0.0
    sigma_p, sigma_q = height / 2.0, width / 4.0
    # float64 on the CPU (some accelerators lack float64), computed once per size and cached by the attack
    p = torch.arange(start, end, dtype=torch.float64)[:, None]
    q = torch.arange(width, dtype=torch.float64)[None, :]
    a = (p - start - sigma_p) ** 2 / sigma_p**2
    b = (q - width / 2.0) ** 2 / sigma_q**2
    norm = 1.0 / (2.0 * math.pi * sigma_p * sigma_q * math.sqrt(1.0 - rho**2))
    profile = norm * torch.exp(-(a + b) / (2.0 * (1.0 - rho**2))) * (height * width)
    return profile.to(device=device, dtype=torch.float32)


def _band_gain(strength: torch.Tensor, color_fractions: torch.Tensor, device: torch.device) -> torch.Tensor:
    """Per-sample, per-channel strength ``S * fraction`` (grey levels), ``(B, 3)``, or ``(1, 3)`` when shared."""
    gain = strength.reshape(-1, 1).to(device, torch.float32) * color_fractions.reshape(-1, 3).to(device)
    return gain[:1] if bool((gain == gain[:1]).all()) else gain


def strip_increment(gain: torch.Tensor, profile: torch.Tensor, dtype: torch.dtype) -> torch.Tensor:
    """What the band gains, ``(B or 1, 3, rows, W)``: float ``gain * profile / 255`` or uint8 ``round(gain * profile)``
    (capped at 255; the sum is saturated where it is added, so adding it equals rounding the float sum)."""
    increment = gain[:, :, None, None] * profile
    if dtype == torch.uint8:
        # float -> int16 -> uint8: 3x faster than a direct float -> uint8 cast on the CPU (values are 0..255)
        return increment.round_().clamp_(max=255.0).to(torch.int16).to(torch.uint8)
    return increment.div_(255.0).to(dtype)


def add_strip(
    x: torch.Tensor,
    strength: torch.Tensor,
    color_fractions: torch.Tensor,
    profile: torch.Tensor,
    increment: torch.Tensor | None = None,
) -> torch.Tensor:
    """Add ``strength * fraction * profile`` (grey levels) to the band of RGB ``x`` ``(B, 3, H, W)``, clipped.

    uint8 ``x`` stays uint8 (a saturating add: ``x + min(increment, 255 - x)``); float ``x`` gets ``/ 255`` and
    [0, 1] (the whole output is clamped, so the result is always in range). ``increment`` (from
    ``strip_increment``) may be passed in by a caller that caches it.
    """
    start, end = band_rows(x.shape[-2])
    out = x.clone() if x.dtype == torch.uint8 else x.clamp(0.0, 1.0)
    if end <= start:
        return out
    if increment is None:
        increment = strip_increment(_band_gain(strength, color_fractions, x.device), profile, x.dtype)
    band = out[:, :, start:end]
    if x.dtype == torch.uint8:
        band.add_(torch.minimum(band.bitwise_not(), increment))  # bitwise_not of uint8 is 255 - value
    else:
        band.add_(increment).clamp_(max=1.0)
    return out


def laser_color_strip(
    image: torch.Tensor,
    strength: float | torch.Tensor,
    color_fractions: Sequence[float] | torch.Tensor = PAPER_COLOR_FRACTIONS,
) -> torch.Tensor:
    """Appendix A's laser color strip with strength ``S`` (grey-level units; float or one per sample) and colour
    fractions (R, G, B) (``(3,)`` or one triple per sample). Returns the image's dtype, shape and device; uint8
    images are computed in uint8 (within one grey level of the float path: the increment is rounded once)."""
    check_image(image)
    s = torch.as_tensor(strength, dtype=torch.float32).reshape(-1)
    fractions = torch.as_tensor(color_fractions, dtype=torch.float32)
    if not bool((s >= 0).all()) or not bool(torch.isfinite(s).all()):
        raise ValueError(f"strength must be finite and >= 0, got {strength!r}")
    if fractions.shape[-1] != 3 or not bool((fractions >= 0).all()):
        raise ValueError(f"color_fractions must be non-negative (R, G, B) triples, got {color_fractions!r}")
    if image.dtype == torch.uint8:
        x, keep_alpha = to_rgb(image)
        profile = strip_profile(*x.shape[-2:], device=x.device)
        return from_uint8_rgb(add_strip(x, s, fractions, profile), keep_alpha, image)
    x, keep_alpha = to_float_rgb(image)
    profile = strip_profile(*x.shape[-2:], device=x.device)
    return from_float_rgb(add_strip(x, s, fractions, profile), keep_alpha, image, in_unit_range=True)


class LaserColorStrip(CameraAttack):
    """Laser color strip; see the module docstring. ``levels`` overrides the strength table (grey-level units)."""

    name: ClassVar[str] = "laser_color_strip"
    _apply_in_unit_range: ClassVar[bool] = True
    # the authors' adversarial training: strength uniform in [500, 2500] (levels=None: the instance's ``levels``)
    random_parameter: ClassVar[RandomParameter] = RandomParameter(500.0, 2500.0)

    def __init__(
        self,
        intensity: IntensitySpec = "medium",
        *,
        color_fractions: Sequence[float] = PAPER_COLOR_FRACTIONS,
        levels: Sequence[float] = STRENGTH_LEVELS,
        model: str = "paper",
        frequency_hz: float = 60.0,
        duty: float = 0.1,
        exposure_s: float = 1e-3,
        row_time_s: float = 1.0 / (30.0 * 720.0),
        frame_rows: int = 720,
        integration_offset_s: float = 0.0,
        edge_threshold: float = 0.0,
        gamma: float | None = None,
        shoulder: float | None = None,
        shoulder_exponent: float = 1.0,
        seed: int | None = None,
        generator: torch.Generator | None = None,
    ) -> None:
        super().__init__(intensity, seed=seed, generator=generator)
        self.levels = check_levels(levels, "laser color strip strength")
        # model="rolling_shutter" (lerobot-phantom-calibrate): rows lit where their exposure window overlaps a
        # laser pulse (physics.rolling_shutter_row_light); the stripe phase is random per sample
        if model not in ("paper", "rolling_shutter"):
            raise ValueError(f"unknown laser color strip model {model!r}; valid: 'paper', 'rolling_shutter'")
        if (
            frequency_hz <= 0
            or not (0.0 < duty <= 1.0)
            or exposure_s < 0
            or row_time_s <= 0
            or frame_rows < 1
        ):
            raise ValueError(
                "rolling shutter needs frequency_hz > 0, duty in (0, 1], exposure_s >= 0, row_time_s > 0"
            )
        # gamma / shoulder (rolling shutter only): the laser's light adds to the scene's in linear irradiance, the
        # pixels decoded by the power law x ** gamma (lerobot-phantom-calibrate's sensor_gamma) or the shouldered
        # curve (its tone_shoulder) and re-encoded after
        self.tone = physics.tone_options(gamma, shoulder, shoulder_exponent, owner="LaserColorStrip")
        if self.tone is not None and (model != "rolling_shutter" or not (gamma is None or gamma > 0)):
            raise ValueError(
                f"gamma={gamma!r}, shoulder={shoulder!r} need model='rolling_shutter' and gamma > 0 (None: add to "
                "the encoded values)"
            )
        self.model = model
        self.rolling_shutter = {
            "frequency_hz": float(frequency_hz),
            "duty": float(duty),
            "exposure_s": float(exposure_s),
            "row_time_s": float(row_time_s),
            "frame_rows": int(frame_rows),
            "integration_offset_s": float(integration_offset_s),
            "edge_threshold": float(
                edge_threshold
            ),  # the measurement's detection threshold, kept for reference
        }
        fractions = tuple(float(v) for v in color_fractions)
        if len(fractions) != 3 or any(not (0.0 <= v <= 1.0) for v in fractions):
            raise ValueError(
                f"color_fractions must be three values in [0, 1] (R, G, B), got {color_fractions!r}"
            )
        self.color_fractions = fractions

    def _sample(
        self,
        s: torch.Tensor,
        height: int,
        width: int,
        generator: torch.Generator | None,
        device: torch.device | str | None,
    ) -> dict[str, torch.Tensor]:
        fractions = torch.tensor(self.color_fractions, dtype=torch.float32, device=device)
        params = {
            "strength": interpolate_levels(s, self.levels),
            "color_fractions": fractions.expand(s.shape[0], 3).clone(),
        }
        if self.model == "rolling_shutter":
            period = 1.0 / self.rolling_shutter["frequency_hz"]
            if generator is None:
                params["phase_s"] = torch.zeros(s.shape[0], device=device)
            else:
                u = torch.rand(s.shape[0], generator=generator, device=generator.device)
                params["phase_s"] = (u * period).to(device)
        return params

    def profile(self, height: int, width: int, device: torch.device | str | None = None) -> torch.Tensor:
        """The cached S = 1 band profile for this image size."""
        return self._cached((height, width, str(device)), lambda: strip_profile(height, width, device))

    def _apply(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        if self.model == "rolling_shutter":
            return self._apply_rolling_shutter(x, params)
        return self._apply_paper(x, params)

    def _apply_uint8(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        if self.model == "rolling_shutter":
            return NotImplemented
        return self._apply_paper(x, params)

    def _apply_paper(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        height, width = x.shape[-2:]
        profile = self.profile(height, width, device=x.device)
        gain = _band_gain(params["strength"], params["color_fractions"], x.device)
        increment = None
        if gain.shape[0] == 1:  # one strength for the batch (a level): the increment is cached
            key = ("increment", height, width, str(x.device), x.dtype, tuple(gain[0].tolist()))
            increment = self._cached(key, lambda: strip_increment(gain, profile, x.dtype))
        return add_strip(x, params["strength"], params["color_fractions"], profile, increment)

    def _apply_rolling_shutter(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        height = x.shape[-2]
        rs = self.rolling_shutter
        rows = physics.rolling_shutter_row_light(
            height,
            rs["frequency_hz"],
            rs["duty"],
            rs["exposure_s"],
            rs["row_time_s"] * rs["frame_rows"] / height,  # same readout time at any image height
            integration_offset_s=rs["integration_offset_s"],
            phase_s=params["phase_s"].to(x.device),
            device=x.device,
        )  # (B, H)
        # the paper's peak gain 4 S / pi grey levels, spread over whole rows
        gain = params["strength"].reshape(-1, 1).to(x.device) * (4.0 / math.pi / 255.0)
        added = (gain * params["color_fractions"].reshape(-1, 3).to(x.device))[:, :, None, None]
        if self.tone is not None:
            return physics.encode(physics.decode(x, self.tone) + added * rows[:, None, :, None], self.tone)
        return (x + added * rows[:, None, :, None]).clamp_(0.0, 1.0)

    def extra_repr(self) -> str:
        tone = "" if self.tone is None else f", tone={self.tone!r}"
        return f"{super().extra_repr()}, color_fractions={self.color_fractions}, model={self.model!r}{tone}"
