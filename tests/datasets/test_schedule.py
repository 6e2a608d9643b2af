"""The per-epoch plan: exact counts, stratified intensities, pure in (seed, epoch, index)."""

from __future__ import annotations

import os
import subprocess
import sys
from functools import partial

import pytest
import torch

from lerobot_phantom.datasets.schedule import allocate, attacked_count, plan_channel, sample_seed
from lerobot_phantom.transforms.intensity import interpolate_levels, random_intensities
from lerobot_phantom.transforms.registry import make_attack


def _plan(
    num_items,
    rate=0.3,
    weights=(1.0, 1.0, 1.0),
    intensity_range=(1 / 3, 1.0),
    seed=0,
    epoch=0,
    slots=1,
    quantiles=None,
):
    return plan_channel(
        num_items,
        rate=rate,
        weights=list(weights),
        intensity_range=intensity_range,
        seed=seed,
        epoch=epoch,
        channel="camera",
        num_camera_slots=slots,
        quantiles=quantiles,
    )


@pytest.mark.parametrize(
    ("total", "weights"), [(10, [1, 1, 1]), (7, [3, 1]), (0, [1]), (101, [0.2, 0.5, 0, 0.3])]
)
def test_allocate_sums_and_stays_within_one_of_the_quota(total, weights):
    counts = allocate(total, weights)
    assert sum(counts) == total
    for count, weight in zip(counts, weights, strict=True):
        assert abs(count - total * weight / sum(weights)) < 1.0


def test_attacked_count_rounds_half_up():
    assert attacked_count(0.5, 3) == 2
    assert attacked_count(0.3, 10) == 3
    assert attacked_count(1.0, 7) == 7
    assert attacked_count(0.0, 7) == 0


@pytest.mark.parametrize("num_items", [1, 37, 1000, 4099])
@pytest.mark.parametrize("rate", [0.0, 0.05, 0.3, 0.77, 1.0])
def test_attacked_fraction_is_exact(num_items, rate):
    plan = _plan(num_items, rate=rate)
    attacked = int((plan.choice >= 0).sum())
    assert attacked == attacked_count(rate, num_items)
    assert abs(attacked / num_items - rate) <= 0.5 / num_items + 1e-12


def test_attack_counts_follow_weights_and_intensities_are_stratified():
    weights = [1.0, 2.0, 3.0]
    plan = _plan(3000, rate=0.4, weights=weights, intensity_range=(0.2, 0.8))
    counts = [int((plan.choice == j).sum()) for j in range(3)]
    assert counts == allocate(1200, weights)
    clean = plan.choice < 0
    assert torch.all(plan.intensity[clean] == 0)
    for j, count in enumerate(counts):
        s = plan.intensity[plan.choice == j].double()
        assert s.min() >= 0.2 and s.max() <= 0.8
        # One draw per stratum: the sorted intensities fall one in each of `count` equal bins.
        bins = torch.floor((s - 0.2) / 0.6 * count).clamp(max=count - 1).long()
        assert torch.equal(torch.sort(bins).values, torch.arange(count))


def test_fixed_intensity_is_used_as_is():
    plan = _plan(100, rate=0.5, intensity_range=(2 / 3, 2 / 3))
    assert torch.allclose(plan.intensity[plan.choice >= 0], torch.tensor(2 / 3))


def test_camera_slots_are_dealt_evenly():
    plan = _plan(1000, rate=0.3, slots=2)
    slots = plan.camera_slot[plan.choice >= 0]
    assert sorted(torch.bincount(slots.long()).tolist()) == [150, 150]


def test_plan_is_pure_in_seed_and_epoch():
    # the global RNG in two different states: a plan that drew from it would differ
    torch.manual_seed(1)
    a = _plan(500, seed=3, epoch=2)
    torch.manual_seed(2)
    torch.rand(1000)
    b = _plan(500, seed=3, epoch=2)
    assert torch.equal(a.choice, b.choice) and torch.equal(a.intensity, b.intensity)
    assert not torch.equal(a.choice, _plan(500, seed=3, epoch=3).choice)
    assert not torch.equal(a.choice, _plan(500, seed=4, epoch=2).choice)


def test_sample_seed_is_distinct_and_fits_int64():
    seeds = {sample_seed(0, epoch, index) for epoch in range(3) for index in range(1000)}
    assert len(seeds) == 3000
    assert all(0 <= s < 2**63 for s in seeds)


def test_sample_seed_is_the_same_in_another_process():
    # Python's str hash is salted per process (PYTHONHASHSEED): a seed built on hash() would differ here
    code = "from lerobot_phantom.datasets.schedule import sample_seed; print(sample_seed(5, 1, 7))"
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert int(result.stdout.strip()) == sample_seed(5, 1, 7)


def test_random_intensity_follows_the_attacks_training_distribution():
    """``quantiles`` map the stratified draws through the attack's ``random_parameter``: ultrasound blur's
    ``randint(5, 20)`` px gives P(d < 10 px) = 5/16 (a uniform s over weak..strong gives 1/2)."""
    blur = make_attack("ultrasound_blur", intensity="random")
    blinding = make_attack("laser_blinding", intensity="random")
    plan = _plan(
        4000,
        rate=0.8,
        weights=(1.0, 1.0),
        quantiles=[partial(random_intensities, blur), partial(random_intensities, blinding)],
    )
    s = plan.intensity[plan.choice == 0]
    displacement = torch.round(interpolate_levels(s, blur.random_parameter.levels))
    # stratified: each of the 16 values gets count/16 items to within one item per stratum (tolerance 1/count)
    counts = torch.bincount(displacement.long() - 5, minlength=16)
    assert counts.numel() == 16 and abs(float((displacement < 10).double().mean()) - 5 / 16) <= 1 / s.numel()
    assert int(counts.max() - counts.min()) <= 1
    alpha = interpolate_levels(plan.intensity[plan.choice == 1], blinding.levels).double()
    assert alpha.min() >= 0.1 - 1e-6 and alpha.max() <= 0.9 + 1e-6
    assert abs(float((alpha < 0.5).double().mean()) - 0.5) <= 1 / alpha.numel() + 1e-9  # alpha ~ U[0.1, 0.9]


def test_quantiles_need_one_function_per_slot():
    with pytest.raises(ValueError, match="one quantile function per attack slot"):
        _plan(10, weights=(1.0, 1.0), quantiles=[lambda u: u])
