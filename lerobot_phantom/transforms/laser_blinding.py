"""Laser blinding: a laser aimed into the lens saturates the sensor (paper: Method, "Laser Blinding Attack";
Appendix A, Algorithm "Laser Blinding Attack").

Physics: the beam is spread by the lens into a saturated white core, a ring clipped in the laser's colour and a
glare that floods the frame. The paper blends a recorded pattern in linearly:
``out = clip(img * (1 - alpha) + pattern * alpha)``.

Levels (Table 2, "weight of pattern"): alpha = 0 / 0.1 / 0.5 / 0.9 at s = 0 / weak / medium / strong, linear in
between (``interpolate_levels``); ``"random"`` draws alpha uniform in [0.1, 0.9] (the authors' adversarial training).

Pattern (``pattern=``):

* ``"red"`` (default): a procedural red laser glare with the statistics of the authors' capture ``red.png``
  (``patterns.laser_glare``: white core over a third of the frame, pink ring, red field to the corners; mean colour
  (245, 79, 132) like the capture's, values >= 250 27.3% vs 27.0%), stretched with the frame as the authors'
  resized capture is.
* ``"spot"``: a small procedural spot on a dark frame (``patterns.laser_spot``; its shape is a ``LaserSpot``:
  colour, core radius, power-law halo, crosstalk, flare streaks; sizes relative to the shorter image side).
* a PATH: a user image such as a real capture, resized to the frame with PIL's LANCZOS filter as the authors do.

``position`` places the pattern centre at (x, y) fractions of the width and height (default the centre; an image
pattern is shifted, black filling the uncovered part); ``"random"`` draws it per sample, uniformly in
``position_range`` on both axes, rounded to whole pixels. Only alpha (via the intensity) and, when asked, the
position are random; the pattern is fixed per instance.

``model="physical"`` (written by ``lerobot-phantom-calibrate``) adds the pattern as linear light instead of blending
(``physics.laser_injection``, options in a ``LaserPhysics``); its default pattern is ``"spot"``. A PATH is then a
capture of the laser alone, read as the calibration reads its captures (``capture.read_capture``): its dark level
(the dark room and the black level) is no laser light and is taken out before the light is scaled by the gain (read
over the frame as a dark frame's light varies where ``pattern_dark=PATH`` gives the capture repeated with the laser
off, the calibration's ``pattern_dark`` column, and otherwise as the room's linear gradient read from the capture,
``capture.room_gradient``), its noise is smoothed away and its beam continued below the noise floor, its saturated
core is continued as a Gaussian beam of width ``core_sigma_ref_px`` (with a narrower beam at its centre where
``inner_core_peak`` is above 0: ``capture.core_continued``), and the glare is centred on the capture's spot, added
back where the capture measured the laser (its light holds the glare, less what the dark level took out) and taken
as the larger of glare and continued beam elsewhere; ``position`` moves the reading with the capture. The
auto-exposure is the calibration's meter with ``meter_power`` (the frame scaled by ``k ** a``, ``k`` the exposure at
which its clipped mean reads as the clean frame's on ``physics.meter_pixels``; ``physics.metered_exposure``; each
pixel's channel mean, or with ``meter_reads="luminance"`` its luminance), or the divisor ``auto_exposure``. With
``exposure_spread`` above 0 each sample's laser power is also scaled by ``exp(spread z)``, ``z`` standard normal
drawn per sample: the frame-to-frame exposure an auto-exposing camera gives each scene (``frame_exposure`` in the
calibration). With ``colour_correction`` (9 numbers, a row-major matrix whose rows sum to 1) the camera mixes its
clipped raw channels with that matrix: the pattern's light and the glare's colour are raw light, the scene goes to
the raw channels by the matrix's inverse, and the clipped laser channel's full well, not its light, is taken out of
the others (``colour_correction`` in the calibration). A capture through such a matrix stores the laser's fainter
channels at 0; with ``raw_colour`` (the laser's raw light in each channel over its own channel's, the calibration's
``laser_colour_*``) its laser channel is read alone and spread over the raw channels in that colour, which the glare
takes too, as the calibration reads its pairs' captures.

Deviations from the paper's code: the pattern is generated (or loaded) once and cached per image size instead of
being re-read from disk on every call; randomness comes from the attack's seeded ``torch.Generator``, never the
global RNG; uint8 output is rounded, not truncated (at most 1 grey level apart).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, ClassVar, NamedTuple

import torch

from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.base import (
    REFERENCE_SIZE,
    CameraAttack,
    check_image,
    from_float_rgb,
    to_float_rgb,
)
from lerobot_phantom.transforms.capture import capture_colour, core_continued, read_capture
from lerobot_phantom.transforms.intensity import IntensitySpec, RandomParameter, interpolate_levels
from lerobot_phantom.transforms.patterns import (
    LASER_COLORS,
    check_levels,
    exact_float64,
    laser_glare,
    laser_spot,
    load_pattern_image,
    parse_color,
    resize_pattern,
)

ALPHA_LEVELS: tuple[float, float, float, float] = (0.0, 0.1, 0.5, 0.9)
PROCEDURAL_PATTERNS: tuple[str, ...] = ("red", "spot")


@dataclass(frozen=True)
class LaserSpot:
    """Shape of the ``"spot"`` pattern (``patterns.laser_spot``); radii and widths are fractions of the shorter side."""

    color: str | Sequence[float] = "green"
    core_radius: float = 0.08
    halo_exponent: float = 2.0
    crosstalk: float = 0.25
    streaks: int = 4
    streak_strength: float = 0.3
    streak_width: float = 0.01
    streak_angle: float = 15.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "color", parse_color(self.color))
        if self.streaks < 0:
            raise ValueError(f"streaks must be >= 0, got {self.streaks}")
        laser_spot(1, 1, center=(0.0, 0.0), **self.spot_kwargs())  # validates the shape parameters

    def spot_kwargs(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class LaserPhysics:
    """Options of ``model="physical"`` (``physics.laser_injection``), as ``lerobot-phantom-calibrate`` fits them."""

    gain: float = 1.0
    glare_amplitude: float = 0.0
    glare_exponent: float = 2.0
    glare_scale_ref_px: float = 8.0
    # the auto-exposure: a divisor of the laser's light (``auto_exposure``), or a meter of the frame's clipped
    # light whose exposure factor is raised to ``meter_power`` (physics.inject_linear_light); at most one
    auto_exposure: float = 0.0
    meter_power: float = 0.0
    # what the meter reads of each pixel's light (physics.METER_READS): its channel mean or its luminance
    meter_reads: str = "channel_mean"
    # width (reference pixels) of the Gaussian beam a capture's saturated core is continued as (capture.py's
    # core_continued); None: the core's light held at the full well
    core_sigma_ref_px: float | None = None
    # a narrower beam at the continued core's centre: its peak over the saturated level, 0 for none, and its width
    # (reference pixels; core_continued)
    inner_core_peak: float = 0.0
    inner_core_sigma_ref_px: float = 1.0
    gamma: float | None = None
    # a tone curve whose highlights roll off (physics.ShoulderCurve) under the display power ``gamma`` (None: 1)
    shoulder: float | None = None
    shoulder_exponent: float = 1.0
    # deviation of the log of each sample's laser power factor (the frames' exposures; module docstring)
    exposure_spread: float = 0.0
    # the camera's colour correction matrix (9 numbers, row-major, rows summing to 1) mixing its clipped raw
    # channels; the laser's pattern and colour are then raw light
    colour_correction: tuple[float, ...] | None = None
    # under colour_correction, the laser's raw light in each channel over its own channel's (1 there): a capture
    # stores the fainter channels at 0, so its laser channel is read alone and spread by this colour, the glare's
    # colour too (physics.raw_light_per_stored); None: the capture's stored channels are taken as raw light. A
    # procedural pattern is raw light already and does not read it
    raw_colour: tuple[float, ...] | None = None
    # the tone curve the options give, built (and so checked) once
    _tone: physics.Tone = dataclasses.field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if (
            self.gain < 0
            or self.glare_amplitude < 0
            or self.auto_exposure < 0
            or self.meter_power < 0
            or self.exposure_spread < 0
            or self.glare_scale_ref_px <= 0
            or (self.core_sigma_ref_px is not None and self.core_sigma_ref_px <= 0)
            or self.inner_core_peak < 0
            or self.inner_core_sigma_ref_px <= 0
        ):
            raise ValueError(
                "gain, glare_amplitude, auto_exposure, meter_power, exposure_spread and inner_core_peak must be >= 0, "
                "glare_scale_ref_px, core_sigma_ref_px and inner_core_sigma_ref_px > 0"
            )
        if self.inner_core_peak > 0 and self.core_sigma_ref_px is None:
            raise ValueError(
                f"inner_core_peak {self.inner_core_peak} continues a capture's saturated core: give core_sigma_ref_px "
                "too, or inner_core_peak 0"
            )
        physics.check_meter_reads(self.meter_reads)
        if self.auto_exposure > 0 and self.meter_power > 0:
            raise ValueError(
                "auto_exposure (a divisor) and meter_power (a clipped-light meter) are two auto-exposures: give one"
            )
        tone = physics.tone_options(self.gamma, self.shoulder, self.shoulder_exponent, owner="LaserBlinding")
        object.__setattr__(self, "_tone", tone)
        object.__setattr__(
            self,
            "colour_correction",
            physics.check_colour_correction(self.colour_correction, "LaserBlinding"),
        )
        if self.raw_colour is not None:
            colour = tuple(float(v) for v in self.raw_colour)
            if self.colour_correction is None or len(colour) != 3 or min(colour) < 0 or max(colour) != 1.0:
                raise ValueError(
                    f"raw_colour {self.raw_colour}; valid: None, or with colour_correction 3 numbers >= 0 whose "
                    "largest is 1 (the laser's own channel)"
                )
            object.__setattr__(self, "raw_colour", colour)

    @property
    def tone(self) -> physics.Tone:
        """The tone curve the light is composed in: sRGB (``gamma`` None), the power law ``gamma``, or with
        ``shoulder`` the shouldered curve under the display power ``gamma`` (None: 1)."""
        return self._tone


def _option_fields(kind: type) -> list[dataclasses.Field]:
    """The options of a ``LaserSpot``/``LaserPhysics``: its fields a caller gives (not the ones it derives)."""
    return [f for f in dataclasses.fields(kind) if f.init]


def _options(kind: type, given: Any, flat: dict[str, Any]) -> Any:
    """A ``LaserSpot``/``LaserPhysics`` from an instance, a mapping or None, updated by flat keyword options."""
    names = {f.name for f in _option_fields(kind)}
    mine = {k: flat.pop(k) for k in list(flat) if k in names}
    if given is None:
        return kind(**mine)
    if isinstance(given, Mapping):
        return kind(**{**given, **mine})
    if isinstance(given, kind):
        return dataclasses.replace(given, **mine) if mine else given
    raise TypeError(f"expected a {kind.__name__}, a mapping or None, got {type(given).__name__}")


def _as_batch_values(value: float | torch.Tensor, batch: int, device: torch.device) -> torch.Tensor:
    """A scalar or per-sample value -> float32 ``(batch or 1, 1, 1, 1)`` for broadcasting."""
    values = torch.as_tensor(value, dtype=torch.float32, device=device).reshape(-1)
    if values.numel() not in (1, batch):
        raise ValueError(f"expected 1 or {batch} per-sample values, got {values.numel()}")
    return values.reshape(-1, 1, 1, 1)


class CaptureLight(NamedTuple):
    """What the physical attack reads from a capture at one frame size (``LaserBlinding.capture_light``)."""

    light: torch.Tensor  # (3, H, W) laser light per unit power, in the tone curve's linear light
    measured: torch.Tensor  # (H, W) bool: where the capture measured the laser's light
    offset: torch.Tensor  # (x, y) pixels from the frame's centre to the capture's spot
    dark_radius_px: float  # pixels from the spot at which the dark level was read
    glare_colour: torch.Tensor | None  # (3,) under raw_colour: raw light per unit the laser's channel stores


CHUNK_BYTES = 1 << 20
"""Images are blended in chunks of about this many bytes, so each pass runs in cache: a batch costs no more per
image than a single image."""


UINT8_CHUNK_BYTES = 4 << 20
"""uint8 images are blended through a float32 scratch of about this many bytes: a few images per op (measured at
224x224: 6 images per op 1.3x faster than one, whose per-op overhead dominates), still in the cache."""


def blend(x: torch.Tensor, alpha: torch.Tensor | float, pattern: torch.Tensor) -> torch.Tensor:
    """``clip(x * (1 - alpha) + pattern * alpha)`` on float images in [0, 1] (Appendix A, Laser Blinding).

    ``pattern``: ``(1 or B, 3, H, W)``. Returns a new tensor in [0, 1].
    """
    weight = _as_batch_values(alpha, x.shape[0], x.device)
    pattern = pattern.to(x.dtype)
    out = torch.empty_like(x, memory_format=torch.contiguous_format)
    step = max(1, CHUNK_BYTES // max(1, x[:1].numel() * x.element_size()))
    for start in range(0, x.shape[0], step):
        chunk = slice(start, start + step)
        w = weight[chunk] if weight.shape[0] > 1 else weight
        p = pattern[chunk] if pattern.shape[0] > 1 else pattern
        # a convex combination of values in [0, 1] stays in [0, 1]: the clip only guards patterns out of range
        torch.lerp(x[chunk], p, w, out=out[chunk]).clamp_(0.0, 1.0)
    return out


def laser_blinding(image: torch.Tensor, alpha: float | torch.Tensor, pattern: torch.Tensor) -> torch.Tensor:
    """Blend ``pattern`` into ``image`` with weight ``alpha`` (a float or one value per sample).

    ``image``: uint8 or float [0, 1], ``(C, H, W)`` or ``(B, C, H, W)``. ``pattern``: ``(3, h, w)`` or
    ``(B, 3, h, w)`` (1 or 4 channels accepted; alpha ignored), uint8 or float, resized to the image if needed
    with PIL's LANCZOS filter (bit-exact with the authors' ``Image.resize`` for 8-bit patterns).
    Returns the image's dtype, shape and device.
    """
    check_image(image)
    check_image(pattern)
    if not torch.all((torch.as_tensor(alpha) >= 0) & (torch.as_tensor(alpha) <= 1)):
        raise ValueError(f"alpha must lie in [0, 1], got {alpha!r}")
    x, keep_alpha = to_float_rgb(image)
    flat, _ = to_float_rgb(pattern.to(image.device))
    resized = torch.stack([resize_pattern(p, *x.shape[-2:]) for p in flat])
    return from_float_rgb(blend(x, alpha, resized), keep_alpha, image)


def _offset(grey: torch.Tensor, alpha: float) -> torch.Tensor:
    """``alpha * pattern * 255 + 0.5``: the pattern's share of a rounded uint8 blend."""
    return torch.mul(grey, alpha).add_(0.5)


def shifted(image: torch.Tensor, rows: int, cols: int) -> torch.Tensor:
    """``(C, H, W)`` moved down by ``rows`` and right by ``cols`` whole pixels, zero (False) where it uncovers."""
    height, width = image.shape[-2:]
    out = torch.zeros_like(image)
    out[:, max(0, rows) : height + min(0, rows), max(0, cols) : width + min(0, cols)] = image[
        :, max(0, -rows) : height - max(0, rows), max(0, -cols) : width - max(0, cols)
    ]
    return out


def _parse_position(position: str | Sequence[float]) -> tuple[float, float] | None:
    """``"center"`` / ``(x, y)`` fractions -> the pair; ``"random"`` -> None."""
    if isinstance(position, str):
        if position == "random":
            return None
        if position == "center":
            return (0.5, 0.5)
        raise ValueError(
            f"unknown position {position!r}; valid: 'center', 'random' or an (x, y) pair in [0, 1]"
        )
    pair = tuple(float(v) for v in position)
    if len(pair) != 2 or not all(0.0 <= v <= 1.0 for v in pair):
        raise ValueError(f"position must be 'center', 'random' or an (x, y) pair in [0, 1], got {position!r}")
    return pair


class LaserBlinding(CameraAttack):
    """Laser blinding; see the module docstring. ``levels`` overrides the alpha table (identity, weak, medium, strong).

    ``spot`` (a ``LaserSpot``) shapes the ``"spot"`` pattern and ``physics`` (a ``LaserPhysics``) the physical
    model; either may be a mapping, and their fields are also accepted as flat keyword options (``color="red"``,
    ``core_radius=0.05``, ``gain=1.5``: the form ``calibrated.json`` files store). Without ``pattern``, spot
    options or ``model="physical"`` select the ``"spot"`` pattern, otherwise the ``"red"`` glare.
    """

    name: ClassVar[str] = "laser_blinding"
    # the authors' adversarial training: weight uniform in [0.1, 0.9] per attacked sample
    random_parameter: ClassVar[RandomParameter] = RandomParameter(0.1, 0.9)

    def __init__(
        self,
        intensity: IntensitySpec = "medium",
        *,
        pattern: str | Path | None = None,
        pattern_dark: str | Path | None = None,
        position: str | Sequence[float] = "center",
        position_range: Sequence[float] = (0.15, 0.85),
        levels: Sequence[float] = ALPHA_LEVELS,
        model: str = "paper",
        spot: LaserSpot | Mapping[str, Any] | None = None,
        physics: LaserPhysics | Mapping[str, Any] | None = None,
        seed: int | None = None,
        generator: torch.Generator | None = None,
        **options: Any,
    ) -> None:
        super().__init__(intensity, seed=seed, generator=generator)
        self.levels = check_levels(levels, "laser blinding alpha", upper=1.0)
        if model not in ("paper", "physical"):
            raise ValueError(f"unknown laser blinding model {model!r}; valid: 'paper', 'physical'")
        self.model = model
        # the paper's blend returns a fresh tensor in [0, 1]: the base skips its final clamp
        self._apply_in_unit_range = model == "paper"
        flat = dict(options)
        spot_given = spot is not None or any(f.name in flat for f in _option_fields(LaserSpot))
        self.spot = _options(LaserSpot, spot, flat)
        self.physics = _options(LaserPhysics, physics, flat)
        if flat:
            valid = [f.name for kind in (LaserSpot, LaserPhysics) for f in _option_fields(kind)]
            raise TypeError(f"LaserBlinding got unknown options {sorted(flat)}; valid: {', '.join(valid)}")
        changed = [f.name for f in _option_fields(LaserPhysics) if getattr(self.physics, f.name) != f.default]
        if model == "paper" and changed:
            raise ValueError(
                f"LaserBlinding options {changed} are the physical model's; pass model='physical' (the paper's "
                "blend takes alpha levels only)"
            )
        if pattern is None:  # spot options ask for the spot; the physical model was calibrated with it
            pattern = "spot" if model == "physical" or spot_given else "red"
        text = str(pattern)
        if text == "red" and spot_given:
            raise ValueError(
                "spot options (color, core_radius, ...) shape pattern='spot', not the 'red' glare"
            )
        if text in PROCEDURAL_PATTERNS:
            self.pattern = text
            self._user_pattern = None
        elif isinstance(pattern, Path) or Path(text).suffix:
            self.pattern = text
            # Loaded once here (not on every call, the paper code's defect); travels with the pickle.
            self._user_pattern = load_pattern_image(text, keep_alpha=False)
        else:
            raise ValueError(
                f"unknown laser pattern {pattern!r}; valid: {', '.join(PROCEDURAL_PATTERNS)} or an image path"
            )
        self.pattern_dark = None if pattern_dark is None else str(pattern_dark)
        self._user_dark = None
        if pattern_dark is not None:
            if model != "physical" or self._user_pattern is None:
                raise ValueError(
                    "pattern_dark (the capture repeated with the laser off) is read with a capture: pass "
                    "model='physical' and pattern=PATH of the capture"
                )
            self._user_dark = load_pattern_image(self.pattern_dark, keep_alpha=False)
            if self._user_dark.shape != self._user_pattern.shape:
                raise ValueError(
                    f"pattern_dark {self.pattern_dark!r} is {tuple(self._user_dark.shape)} but the capture "
                    f"{self.pattern!r} is {tuple(self._user_pattern.shape)}: a dark frame repeats its capture"
                )
        # the laser colour of the physical model's glare halo
        self.color = LASER_COLORS["red"] if self.pattern == "red" else self.spot.color
        # under raw_colour a capture is read in its laser channel alone: the one holding most of its light
        self._laser_channel = None
        if model == "physical" and self._user_pattern is not None and self.physics.raw_colour is not None:
            self._laser_channel = int(capture_colour(exact_float64(self._user_pattern)).argmax())
            if self.physics.raw_colour[self._laser_channel] != 1.0:
                raise ValueError(
                    f"raw_colour {self.physics.raw_colour} is the laser's light over its own channel's, which must "
                    f"be 1: the capture {self.pattern!r} holds its laser light in channel {self._laser_channel}"
                )
        self.position = position
        self._fixed_position = _parse_position(position)
        low, high = (float(v) for v in position_range)
        if not (0.0 <= low <= high <= 1.0):
            raise ValueError(
                f"position_range must be (low, high) with 0 <= low <= high <= 1, got {position_range!r}"
            )
        self.position_range = (low, high)

    # -- parameters ---------------------------------------------------------------------------------------------
    def _sample(
        self,
        s: torch.Tensor,
        height: int,
        width: int,
        generator: torch.Generator | None,
        device: torch.device | str | None,
    ) -> dict[str, torch.Tensor]:
        batch = s.shape[0]
        if self._fixed_position is None:
            if generator is None:
                raise ValueError("position='random' needs a torch.Generator (pass generator= or seed=)")
            low, high = self.position_range
            u = torch.rand(batch, 2, generator=generator, device=generator.device)
            position = (low + (high - low) * u).to(device)
        else:
            position = torch.tensor(self._fixed_position, dtype=torch.float32, device=device).expand(batch, 2)
        params = {"alpha": interpolate_levels(s, self.levels), "position": position.clone()}
        if self.model == "physical" and self.physics.exposure_spread > 0:
            if generator is None:
                raise ValueError(
                    "exposure_spread > 0 draws each sample's exposure and needs a torch.Generator (pass "
                    "generator= or seed=)"
                )
            z = torch.randn(batch, generator=generator, device=generator.device)
            params["exposure"] = torch.exp(self.physics.exposure_spread * z).to(device)
        return params

    # -- pattern ---------------------------------------------------------------------------------------------------
    def _resized_user_pattern(self, height: int, width: int, device: torch.device) -> torch.Tensor:
        assert self._user_pattern is not None
        return self._cached(
            ("user", height, width, str(device)),
            # contiguous CHW: an image's HWC pixels make every broadcast blend several times slower
            lambda: resize_pattern(self._user_pattern, height, width).to(device).contiguous(),
        )

    def capture_light(self, height: int, width: int, device: torch.device) -> CaptureLight:
        """A capture (``pattern=PATH``) read as the calibration reads its pairs' (``capture.read_capture``, on the
        capture resized to the frame, with its dark frame ``pattern_dark`` where given): its light per unit power
        in the camera's tone curve (the dark level out, the beam continued below the noise floor, the saturated core
        continued when ``core_sigma_ref_px`` is set; under ``raw_colour``, its laser channel spread over the raw
        channels), where it measured the laser, its spot's offset from the frame's centre, the dark level's
        distance from the spot, and the glare's colour under ``raw_colour``."""

        def make() -> CaptureLight:
            p = self.physics
            capture = exact_float64(self._resized_user_pattern(height, width, torch.device("cpu")))
            dark_frame = (
                None
                if self._user_dark is None
                else exact_float64(resize_pattern(self._user_dark, height, width))
            )
            reading = read_capture(capture, dark_frame)
            beam, dark = physics.decode(reading.beam, p.tone), physics.decode(reading.dark, p.tone)
            if p.core_sigma_ref_px is None:
                light = (beam - dark).clamp(min=0.0)
            else:
                light = core_continued(
                    beam,
                    dark,
                    reading.core_depth,
                    reading.core_radius,
                    p.core_sigma_ref_px,
                    p.inner_core_peak,
                    p.inner_core_sigma_ref_px,
                )
            glare_colour = None
            if self._laser_channel is not None:
                channel = self._laser_channel
                glare_colour = physics.raw_light_per_stored(
                    torch.tensor(p.colour_correction, dtype=torch.float64).reshape(3, 3),
                    torch.tensor(p.raw_colour, dtype=torch.float64),
                    channel,
                )
                light = light[channel : channel + 1] * glare_colour.reshape(3, 1, 1)
                glare_colour = glare_colour.float().to(device)
            x, y = reading.centre
            offset = (x - round(0.5 * (width - 1)), y - round(0.5 * (height - 1)))
            return CaptureLight(
                light.float().to(device),
                reading.measured.to(device),
                torch.tensor(offset, device=device),
                reading.dark_radius * max(height, width) / REFERENCE_SIZE,
                glare_colour,
            )

        return self._cached(("capture", height, width, str(device)), make)

    def spot_pixel(self, position: torch.Tensor, height: int, width: int) -> torch.Tensor:
        """(x, y) fractions ``(B, 2)`` -> integer (row, col) pixel centres ``(B, 2)``."""
        rows = torch.round(position[:, 1] * (height - 1))
        cols = torch.round(position[:, 0] * (width - 1))
        return torch.stack([rows, cols], dim=1).long()

    def _procedural(
        self,
        height: int,
        width: int,
        center: tuple[float, float],
        frame: tuple[int, int],
        device: torch.device | str | None,
    ) -> torch.Tensor:
        if self.pattern == "red":
            return laser_glare(height, width, center=center, frame=frame, device=device)
        return laser_spot(
            height, width, center=center, unit=min(frame), device=device, **self.spot.spot_kwargs()
        )

    def render_pattern(
        self, height: int, width: int, row: float, col: float, device: torch.device
    ) -> torch.Tensor:
        """The pattern ``(3, height, width)`` with its centre at pixel (row, col); cached."""

        def make() -> torch.Tensor:
            if self._user_pattern is None:
                return self._procedural(height, width, (float(row), float(col)), (height, width), device)
            base = self._resized_user_pattern(height, width, device)
            return shifted(
                base, round(row) - round(0.5 * (height - 1)), round(col) - round(0.5 * (width - 1))
            )

        return self._cached(("single", height, width, row, col, str(device)), make)

    def _canvas(self, height: int, width: int, device: torch.device) -> torch.Tensor:
        """A ``(3, 2H-1, 2W-1)`` canvas with the pattern centred at (H-1, W-1): crops give every position."""

        def make() -> torch.Tensor:
            if self._user_pattern is None:
                return self._procedural(
                    2 * height - 1, 2 * width - 1, (height - 1.0, width - 1.0), (height, width), device
                )
            canvas = torch.zeros(3, 2 * height - 1, 2 * width - 1, device=device)
            top, left = height - 1 - round(0.5 * (height - 1)), width - 1 - round(0.5 * (width - 1))
            canvas[:, top : top + height, left : left + width] = self._resized_user_pattern(
                height, width, device
            )
            return canvas

        return self._cached(("canvas", height, width, str(device)), make)

    def patterns_for(
        self, position: torch.Tensor, height: int, width: int, device: torch.device
    ) -> torch.Tensor:
        """Patterns ``(B or 1, 3, H, W)`` for per-sample positions ``(B, 2)``."""
        if self._fixed_position is not None:
            # a fixed position is exact (the glare centred between pixels on an even frame, as the resized capture)
            px, py = self._fixed_position
            return self.render_pattern(height, width, py * (height - 1), px * (width - 1), device)[None]
        pixels = self.spot_pixel(position.to(device), height, width)
        # random positions: crop the cached canvas (a view when one position serves the whole batch)
        canvas = self._canvas(height, width, device)
        if bool((pixels == pixels[:1]).all()):
            top, left = height - 1 - int(pixels[0, 0]), width - 1 - int(pixels[0, 1])
            return canvas[None, :, top : top + height, left : left + width]
        rows = (height - 1 - pixels[:, :1]) + torch.arange(height, device=device)
        cols = (width - 1 - pixels[:, 1:]) + torch.arange(width, device=device)
        return canvas[:, rows[:, :, None], cols[:, None, :]].permute(1, 0, 2, 3)

    # -- application ----------------------------------------------------------------------------------------------
    def _apply(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        if self.model == "physical":
            return self._apply_physical(x, params)
        height, width = x.shape[-2:]
        return blend(x, params["alpha"], self.patterns_for(params["position"], height, width, x.device))

    def _apply_uint8(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        """The paper's blend on uint8 ``(N, 3, H, W)`` without a batch-sized float copy.

        A few images at a time in a float32 scratch that stays in cache (one op per chunk, not per image), rounded
        by adding 0.5 and truncating through int16 (the fast float -> uint8 route). A chunk at one of the level
        table's alphas with a fixed position blends as ``x * (1 - alpha) + q`` with ``q = alpha * pattern * 255 +
        0.5`` cached; other chunks ``lerp`` with per-sample weights. The float path rounds the same blend: equal up
        to rounding ties.
        """
        if self.model != "paper":
            return NotImplemented
        batch, _, height, width = x.shape
        pattern = self.patterns_for(params["position"], height, width, x.device)
        alphas = params["alpha"].to(x.device, torch.float32).reshape(-1).expand(batch)
        values = alphas.tolist()
        cacheable = self._fixed_position is not None
        grey = (
            self._cached(("grey", height, width, str(x.device)), lambda: pattern * 255.0)
            if cacheable
            else None
        )
        per_chunk = min(batch, max(1, UINT8_CHUNK_BYTES // (x[0].numel() * 4)))
        out = torch.empty(x.shape, dtype=torch.uint8, device=x.device)
        scratch = torch.empty((per_chunk, *x.shape[1:]), dtype=torch.float32, device=x.device)
        as_int16 = torch.empty(scratch.shape, dtype=torch.int16, device=x.device)
        for start in range(0, batch, per_chunk):
            chunk = slice(start, start + per_chunk)
            size = len(values[chunk])
            blended = scratch[:size].copy_(x[chunk])
            alpha = values[start]
            level = min(self.levels, key=lambda v: abs(v - alpha))
            if cacheable and abs(level - alpha) < 1e-7 and values[chunk] == [alpha] * size:
                # a paper level for the whole chunk: at most 4 cached offsets per size
                q = self._cached(
                    ("offset", height, width, level, str(x.device)), partial(_offset, grey[0], alpha)
                )
                torch.add(q, blended, alpha=1.0 - alpha, out=blended)
            else:
                target = grey if grey is not None else pattern[chunk] * 255.0
                blended.lerp_(target, alphas[chunk].reshape(-1, 1, 1, 1)).add_(0.5)
            as_int16[:size].copy_(blended)  # values in [0.5, 255.5]: truncation rounds
            out[chunk].copy_(as_int16[:size])
        return out

    def _apply_physical(self, x: torch.Tensor, params: dict[str, torch.Tensor]) -> torch.Tensor:
        height, width = x.shape[-2:]
        p = self.physics
        pixels = self.spot_pixel(params["position"].to(x.device), height, width)
        centre = pixels.flip(1).to(x.dtype)
        measured, dark_radius_px = None, 0.0
        glare_colour = torch.tensor(self.color, dtype=x.dtype, device=x.device)
        if self._user_pattern is None:
            pattern = self.patterns_for(params["position"], height, width, x.device)
            light = physics.decode(pattern.to(x.dtype), p.tone)
        else:
            # the capture's reading, moved as position moves the capture (whole pixels; nothing measured where
            # the capture does not reach)
            reading = self.capture_light(height, width, x.device)
            read, read_measured, dark_radius_px = reading.light, reading.measured, reading.dark_radius_px
            centre = centre + reading.offset.to(x.dtype)
            if reading.glare_colour is not None:
                glare_colour = reading.glare_colour.to(x.dtype)
            moves = (
                pixels - pixels.new_tensor([round(0.5 * (height - 1)), round(0.5 * (width - 1))])
            ).tolist()
            if all(move == moves[0] for move in moves):
                moves = moves[:1]  # one reading serves the batch
            light = torch.stack([shifted(read, dy, dx) for dy, dx in moves])
            measured = torch.stack([shifted(read_measured[None], dy, dx) for dy, dx in moves])
        return physics.laser_injection(
            x,
            light,
            params["intensity"].to(x.device) * p.gain * params.get("exposure", torch.ones(())).to(x.device),
            centre=centre,
            color=glare_colour,
            halo_amplitude=p.glare_amplitude,
            halo_exponent=p.glare_exponent,
            halo_scale_px=p.glare_scale_ref_px * max(height, width) / REFERENCE_SIZE,
            measured=measured,
            dark_radius_px=dark_radius_px,
            auto_exposure=p.auto_exposure,
            meter_power=p.meter_power,
            meter_reads=p.meter_reads,
            gamma=p.tone,
            colour_correction=None
            if p.colour_correction is None
            else torch.tensor(p.colour_correction, dtype=torch.float64).reshape(3, 3),
        )

    def extra_repr(self) -> str:
        dark = "" if self.pattern_dark is None else f", pattern_dark={self.pattern_dark!r}"
        where = f"position={self.position!r}, model={self.model!r}"
        return f"{super().extra_repr()}, pattern={self.pattern!r}{dark}, {where}"
