"""The exact, reproducible choice of which samples are attacked, by what, how hard, on which camera.

One *channel* (the camera/main channel driven by ``--phantom.rate``/``attacks``, or the instruction channel driven
by ``--phantom.instruction_rate``/``instruction_attacks``) is planned per epoch, for all ``N`` items at once:

1. a permutation of the ``N`` items, drawn from a generator seeded with ``(seed, epoch, channel)``;
2. the first ``k = round(rate * N)`` positions of the permutation are attacked, so the attacked fraction over the
   epoch is exactly ``k / N`` (off from ``rate`` by at most ``1 / (2N)``), not merely ``rate`` in expectation;
3. those ``k`` positions are split between the attacks in proportion to their weights (largest remainder), so the
   per-attack counts are exact too;
4. within each attack's share, intensities are stratified: the share is cut into ``count`` equal strata of
   [0, 1) and each item gets a uniform draw ``u`` inside its own stratum (a Latin-hypercube draw: uniform
   marginally, the histogram over an epoch flat to within one item per stratum), mapped to an intensity by the
   slot's quantile function: ``low + (high - low) * u`` for an intensity range, or, for ``"random"``, the
   attack's adversarial-training distribution (``intensity.random_intensities``: e.g. ultrasound blur's
   ``randint(5, 20)`` px), so its epoch histogram follows that distribution to within one item per stratum;
5. for ``--phantom.cameras=[random]``, the camera slots are dealt evenly over the attacked items the same way.

Nothing depends on the number of dataloader workers, on the sampler order or on the process rank: item ``i``'s
decision is a pure function of ``(seed, epoch, i)`` (and of ``N`` and the config). Each sample's attack parameters
come from ``sample_seed(seed, epoch, i)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import torch

from lerobot_phantom.transforms.base import derive_seed

CAMERA_CHANNEL = "camera"
INSTRUCTION_CHANNEL = "instruction"


def attacked_count(rate: float, num_items: int) -> int:
    """``round(rate * num_items)``, half rounding up (not Python's banker's rounding)."""
    return min(num_items, math.floor(rate * num_items + 0.5))


def allocate(total: int, weights: Sequence[float]) -> list[int]:
    """Split ``total`` into integer counts proportional to ``weights`` (largest remainder; ties: first entry)."""
    weight_sum = float(sum(weights))
    if total < 0 or not weights or weight_sum <= 0:
        raise ValueError(f"cannot allocate {total} items over weights {list(weights)}")
    quotas = [total * float(w) / weight_sum for w in weights]
    counts = [math.floor(q) for q in quotas]
    by_remainder = sorted(range(len(weights)), key=lambda j: (-(quotas[j] - counts[j]), j))
    for j in by_remainder[: total - sum(counts)]:
        counts[j] += 1
    return counts


def sample_seed(seed: int, epoch: int, index: int) -> int:
    """The seed of item ``index``'s attack parameters (63-bit, fits an int64 label)."""
    return derive_seed("phantom-sample", int(seed), int(epoch), int(index))


@dataclass(frozen=True)
class ChannelPlan:
    """One epoch of one channel: per item, the attack slot (-1 = clean), intensity and camera slot."""

    choice: torch.Tensor  # int16 (N,): index into the channel's attack list, -1 for clean items
    intensity: torch.Tensor  # float32 (N,): 0 for clean items
    camera_slot: torch.Tensor  # int16 (N,): index into the attackable cameras (used by cameras=[random])

    @property
    def num_items(self) -> int:
        return int(self.choice.numel())


def plan_channel(
    num_items: int,
    *,
    rate: float,
    weights: Sequence[float],
    intensity_range: tuple[float, float],
    seed: int,
    epoch: int,
    channel: str,
    num_camera_slots: int = 1,
    quantiles: Sequence[Callable[[torch.Tensor], torch.Tensor]] | None = None,
) -> ChannelPlan:
    """Plan one channel for one epoch (see the module docstring for the construction).

    ``quantiles``: one function per attack slot (same order as ``weights``) from stratified uniform draws ``u``
    in [0, 1) to intensities in [0, 1] (``intensity.random_intensities`` bound to the attack, for ``"random"``);
    ``None`` spreads ``u`` uniformly over ``intensity_range``.
    """
    if num_items < 0:
        raise ValueError(f"num_items must be >= 0, got {num_items}")
    if num_camera_slots < 1:
        raise ValueError(f"num_camera_slots must be >= 1, got {num_camera_slots}")
    if quantiles is not None and len(quantiles) != len(weights):
        raise ValueError(f"need one quantile function per attack slot ({len(weights)}), got {len(quantiles)}")
    generator = torch.Generator().manual_seed(derive_seed("phantom-plan", int(seed), int(epoch), channel))
    choice = torch.full((num_items,), -1, dtype=torch.int16)
    intensity = torch.zeros(num_items, dtype=torch.float32)
    camera_slot = torch.zeros(num_items, dtype=torch.int16)
    attacked = attacked_count(rate, num_items)
    if attacked == 0:
        return ChannelPlan(choice, intensity, camera_slot)

    order = torch.randperm(num_items, generator=generator)[:attacked]
    low, high = intensity_range
    start = 0
    for slot, count in enumerate(allocate(attacked, weights)):
        if count == 0:
            continue
        members = order[start : start + count]
        start += count
        choice[members] = slot
        strata = torch.randperm(count, generator=generator).to(torch.float64)
        jitter = torch.rand(count, generator=generator, dtype=torch.float64)
        u = (strata + jitter) / count
        if quantiles is None:
            intensity[members] = (low + (high - low) * u).to(torch.float32)
        else:
            intensity[members] = quantiles[slot](u).to(torch.float32).reshape(count)
    camera_slot[order] = (torch.randperm(attacked, generator=generator) % num_camera_slots).to(torch.int16)
    return ChannelPlan(choice, intensity, camera_slot)
