"""Intensity conventions shared by every attack.

An attack's strength is one number ``s`` in [0, 1]: ``s = 0`` is the identity and distortion grows with ``s``.
The paper's three levels (Table 2) sit at fixed points of that scale, the same for every attack:

    weak = 1/3, medium = 2/3, strong = 1

Each attack maps ``s`` to its physical parameter piecewise-linearly through
``(0, identity), (1/3, weak), (2/3, medium), (1, strong)`` (see ``interpolate_levels``), so that "random between
weak and strong" means ``s ~ U(1/3, 1)`` for every attack.

Accepted ``intensity`` values: a level name, ``"random"`` (= ``(1/3, 1)``), a float in [0, 1], a ``(low, high)``
pair sampled uniformly per sample, or a string ``"0.2"`` / ``"0.2:0.8"`` (the CLI form).
"""

from __future__ import annotations

from collections.abc import Sequence

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
