"""Intensity conventions shared by every attack.

An attack's strength is one number ``s`` in [0, 1]: ``s = 0`` is the identity and distortion grows with ``s``.
The paper's three levels (Table 2) sit at fixed points of that scale, the same for every attack:

    weak = 1/3, medium = 2/3, strong = 1

Each attack maps ``s`` to its physical parameter piecewise-linearly through
``(0, identity), (1/3, weak), (2/3, medium), (1, strong)`` (see ``interpolate_levels``), so that "random between
weak and strong" means ``s ~ U(1/3, 1)`` for every attack.

Accepted ``intensity`` values: a level name, ``"random"``, a float in [0, 1], a ``(low, high)`` pair (``s``
uniform in it, per sample), or a string ``"0.2"`` / ``"0.2:0.8"`` (the CLI form).

``"random"`` draws the authors' adversarial-training distribution of the attack's *physical* parameter when the
attack declares one (class attribute ``random_parameter``, a ``RandomParameter``), e.g. ultrasound blur
displacement ``randint(5, 20)`` px, laser blinding alpha ``U[0.1, 0.9]``; the reported per-sample ``s`` is that
value pushed back through the attack's level map (``intensity_for``), so labels stay in [0, 1] and
``interpolate_levels(s, levels)`` gives the drawn value back. Attacks without a declaration (the instruction
attacks) draw ``s ~ U(1/3, 1)`` (``RANDOM_RANGE``), as does an explicit ``(1/3, 1)`` for every attack.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import torch

LEVELS: dict[str, float] = {"weak": 1.0 / 3.0, "medium": 2.0 / 3.0, "strong": 1.0}
RANDOM_RANGE: tuple[float, float] = (LEVELS["weak"], LEVELS["strong"])

IntensitySpec = str | float | int | tuple[float, float] | Sequence[float]

_VALID_TEXT = (
    "a level ('weak', 'medium', 'strong'), 'random', a float in [0, 1], or a (low, high) range in [0, 1]"
)


def _check_unit(value: float, what: str) -> float:
    value = float(value)
    if not (0.0 <= value <= 1.0):  # also rejects NaN
        raise ValueError(f"{what} must lie in [0, 1], got {value!r}; intensity is {_VALID_TEXT}")
    return value


def parse_intensity(intensity: IntensitySpec) -> tuple[float, float]:
    """Return the ``(low, high)`` range of ``s`` an intensity spec stands for (``low == high`` when fixed)."""
    if isinstance(intensity, bool):
        raise ValueError(f"intensity must be {_VALID_TEXT}, got {intensity!r}")
    if isinstance(intensity, str):
        text = intensity.strip().lower()
        if text in LEVELS:
            return LEVELS[text], LEVELS[text]
        if text == "random":
            return RANDOM_RANGE
        try:
            parts = [float(p) for p in text.split(":")]
        except ValueError:
            raise ValueError(f"unknown intensity {intensity!r}; valid: {_VALID_TEXT}") from None
        if len(parts) == 1:
            return parse_intensity(parts[0])
        if len(parts) == 2:
            return parse_intensity((parts[0], parts[1]))
        raise ValueError(f"unknown intensity {intensity!r}; valid: {_VALID_TEXT}")
    if isinstance(intensity, int | float):
        value = _check_unit(intensity, "intensity")
        return value, value
    if isinstance(intensity, Sequence) and len(intensity) == 2:
        low = _check_unit(intensity[0], "intensity low")
        high = _check_unit(intensity[1], "intensity high")
        if low > high:
            raise ValueError(
                f"intensity range needs low <= high, got ({low}, {high}); intensity is {_VALID_TEXT}"
            )
        return low, high
    raise ValueError(f"intensity must be {_VALID_TEXT}, got {intensity!r}")


def sample_intensity(
    intensity_range: tuple[float, float],
    batch_size: int,
    generator: torch.Generator | None,
    device: torch.device | str | None = None,
) -> torch.Tensor:
    """Per-sample intensities, shape ``(batch_size,)``; draws from ``generator`` only when the range is open."""
    low, high = intensity_range
    if low == high:
        return torch.full((batch_size,), low, dtype=torch.float32, device=device)
    if generator is None:
        raise ValueError("a random intensity range needs a torch.Generator (pass generator= or seed=)")
    u = torch.rand(batch_size, generator=generator, dtype=torch.float32, device=generator.device)
    return (low + (high - low) * u).to(device)


def interpolate_levels(s: torch.Tensor, points: Sequence[float]) -> torch.Tensor:
    """Map intensity ``s`` to a physical parameter through ``points`` = values at s = 0, 1/3, 2/3, 1."""
    if len(points) != 4:
        raise ValueError(f"need 4 level points (identity, weak, medium, strong), got {len(points)}")
    knots = torch.tensor(points, dtype=torch.float32, device=s.device)
    pos = s.to(torch.float32).clamp(0.0, 1.0) * 3.0
    idx = pos.floor().clamp(max=2).long()
    frac = pos - idx.to(torch.float32)
    return knots[idx] + (knots[idx + 1] - knots[idx]) * frac


def is_random(intensity: IntensitySpec | torch.Tensor | None) -> bool:
    """Whether a spec is the word ``"random"`` (the authors' training distribution), not an explicit range."""
    return isinstance(intensity, str) and intensity.strip().lower() == "random"


def intensity_for(values: torch.Tensor, points: Sequence[float]) -> torch.Tensor:
    """Inverse of ``interpolate_levels``: the intensity ``s`` at which the level map reaches ``values``.

    ``points`` (values at s = 0, 1/3, 2/3, 1) must be non-decreasing; where the map is flat the largest such ``s``
    is returned (so a weak value maps to 1/3 even when the map is flat below weak). Values outside
    ``[points[0], points[3]]`` clamp to s = 0 / 1.
    """
    if len(points) != 4 or any(b < a for a, b in itertools.pairwise(points)):
        raise ValueError(
            f"need 4 non-decreasing level points (identity, weak, medium, strong), got {points!r}"
        )
    v = values.to(torch.float32).contiguous()
    # the map is monotone, so s lies on the last segment whose start is <= v (one vectorised lookup, not a loop)
    starts = torch.tensor(points[:3], dtype=torch.float32, device=v.device)
    segment = torch.searchsorted(starts, v, right=True) - 1
    k = segment.clamp(min=0)
    ends64 = torch.tensor(points, dtype=torch.float64, device=v.device)
    span = (ends64[1:] - ends64[:3]).to(torch.float32)[k]  # as the Python float difference, then float32
    flat = span == 0
    frac = torch.where(
        flat, torch.ones_like(v), ((v - starts[k]) / torch.where(flat, 1.0, span)).clamp(0.0, 1.0)
    )
    return torch.where(segment < 0, torch.zeros_like(v), (k.to(torch.float32) + frac) / 3.0)


@dataclass(frozen=True)
class RandomParameter:
    """The distribution ``"random"`` draws an attack's physical parameter from (the authors' adversarial training).

    ``uniform(low, high)`` when ``integer`` is false; ``randint(low, high)`` with both ends included (Python's
    ``random.randint``, which the authors' code uses) when it is true. ``levels``: the attack's level table
    (values at s = 0, weak, medium, strong) used to report ``s``; ``None`` reads the instance's ``levels``
    attribute (attacks whose table is a constructor option).

    Declare on the attack class::

        class UltrasoundBlur(CameraAttack):
            random_parameter: ClassVar[RandomParameter] = RandomParameter(5, 20, integer=True,
                                                                          levels=LEVEL_DISPLACEMENT_PX)
    """

    low: float
    high: float
    integer: bool = False
    levels: tuple[float, float, float, float] | None = None

    def __post_init__(self) -> None:
        if not (self.low <= self.high):
            raise ValueError(f"RandomParameter needs low <= high, got ({self.low}, {self.high})")
        if self.integer and (self.low != int(self.low) or self.high != int(self.high)):
            raise ValueError(f"an integer RandomParameter needs integer ends, got ({self.low}, {self.high})")

    def quantile(self, u: torch.Tensor) -> torch.Tensor:
        """The parameter value at uniform draw(s) ``u`` in [0, 1) (stratified schedules pass their own ``u``)."""
        u = u.to(torch.float32)
        if self.integer:
            count = self.high - self.low + 1.0
            return (self.low + torch.floor(u * count)).clamp(max=self.high)
        return self.low + (self.high - self.low) * u

    def intensity(self, u: torch.Tensor, points: Sequence[float]) -> torch.Tensor:
        """Per-sample ``s`` for uniform draws ``u``: the quantile's value through the inverse level map."""
        return intensity_for(self.quantile(u), points)


def random_intensities(attack: Any, u: torch.Tensor) -> torch.Tensor:
    """``s`` for uniform draws ``u`` under ``"random"``: the attack's ``RandomParameter`` or ``U(1/3, 1)``."""
    parameter: RandomParameter | None = getattr(attack, "random_parameter", None)
    if parameter is None:
        low, high = RANDOM_RANGE
        return low + (high - low) * u.to(torch.float32)
    points = parameter.levels if parameter.levels is not None else getattr(attack, "levels", None)
    if points is None:
        raise TypeError(
            f"{type(attack).__name__}.random_parameter has no levels and the attack has no 'levels' attribute"
        )
    return parameter.intensity(u, points)


def sample_random_intensity(
    attack: Any,
    batch_size: int,
    generator: torch.Generator | None,
    device: torch.device | str | None = None,
) -> torch.Tensor:
    """Per-sample ``s`` ``(batch_size,)`` for ``intensity="random"``: one uniform draw per sample from ``generator``."""
    if generator is None:
        raise ValueError("a random intensity needs a torch.Generator (pass generator= or seed=)")
    u = torch.rand(batch_size, generator=generator, dtype=torch.float32, device=generator.device)
    return random_intensities(attack, u).to(device)
