import pytest
import torch

from lerobot_phantom.transforms.intensity import (
    LEVELS,
    RANDOM_RANGE,
    interpolate_levels,
    parse_intensity,
    sample_intensity,
)


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        ("weak", (1 / 3, 1 / 3)),
        ("MEDIUM", (2 / 3, 2 / 3)),
        ("strong", (1.0, 1.0)),
        ("random", RANDOM_RANGE),
        (0.25, (0.25, 0.25)),
        (0, (0.0, 0.0)),
        ((0.2, 0.8), (0.2, 0.8)),
        ("0.4", (0.4, 0.4)),
        ("0.2:0.8", (0.2, 0.8)),
    ],
)
def test_parse_intensity_accepts_every_documented_form(spec, expected):
    assert parse_intensity(spec) == pytest.approx(expected)


@pytest.mark.parametrize(
    "spec", ["extreme", 1.5, -0.1, float("nan"), (0.8, 0.2), (0.1, 2.0), "0.1:0.2:0.3", True, None]
)
def test_parse_intensity_rejects_bad_values_naming_valid_ones(spec):
    with pytest.raises(ValueError, match="weak"):
        parse_intensity(spec)


def test_levels_sit_at_thirds():
    assert pytest.approx({"weak": 1 / 3, "medium": 2 / 3, "strong": 1.0}) == LEVELS
    assert (LEVELS["weak"], LEVELS["strong"]) == RANDOM_RANGE


def test_interpolate_levels_hits_the_paper_points_and_is_monotone():
    points = (0.0, 5.0, 10.0, 20.0)
    s = torch.tensor([0.0, LEVELS["weak"], LEVELS["medium"], LEVELS["strong"]])
    assert interpolate_levels(s, points).tolist() == pytest.approx(points, abs=1e-5)
    grid = torch.linspace(0, 1, 101)
    values = interpolate_levels(grid, points)
    assert (values[1:] >= values[:-1]).all()
    assert interpolate_levels(torch.tensor([0.5]), points).item() == pytest.approx(7.5, abs=1e-5)


def test_sample_intensity_is_seeded_and_within_range():
    a = sample_intensity((0.2, 0.8), 64, torch.Generator().manual_seed(3))
    b = sample_intensity((0.2, 0.8), 64, torch.Generator().manual_seed(3))
    c = sample_intensity((0.2, 0.8), 64, torch.Generator().manual_seed(4))
    assert torch.equal(a, b)
    assert not torch.equal(a, c)
    assert ((a >= 0.2) & (a <= 0.8)).all()
    assert a.unique().numel() > 1


def test_fixed_intensity_needs_no_generator_but_a_range_does():
    assert sample_intensity((0.5, 0.5), 3, None).tolist() == [0.5, 0.5, 0.5]
    with pytest.raises(ValueError, match="Generator"):
        sample_intensity((0.2, 0.8), 3, None)


def test_intensity_for_inverts_the_level_map_including_flat_parts():
    from lerobot_phantom.transforms.intensity import intensity_for

    points = (0.0, 5.0, 10.0, 20.0)
    s = torch.linspace(0, 1, 31)
    assert intensity_for(interpolate_levels(s, points), points).tolist() == pytest.approx(
        s.tolist(), abs=1e-5
    )
    # flat below weak (EM colour strip: 8 stripes from s = 0 to weak): the weak value maps to weak, not to 0
    flat = (8.0, 8.0, 12.0, 16.0)
    assert intensity_for(torch.tensor([8.0, 10.0, 16.0, 30.0]), flat).tolist() == pytest.approx(
        [1 / 3, 0.5, 1.0, 1.0]
    )
    with pytest.raises(ValueError, match="non-decreasing"):
        intensity_for(torch.tensor([1.0]), (0.0, 2.0, 1.0, 3.0))


def test_random_parameter_integer_draws_cover_both_ends_uniformly():
    from lerobot_phantom.transforms.intensity import RandomParameter

    blur = RandomParameter(5, 20, integer=True, levels=(0.0, 5.0, 10.0, 20.0))
    u = torch.rand(32000, generator=torch.Generator().manual_seed(0))
    values = blur.quantile(u)
    assert values.unique().tolist() == [float(v) for v in range(5, 21)]
    # the authors' randint(5, 20): P(d < 10) = 5 / 16
    assert (values < 10).float().mean().item() == pytest.approx(5 / 16, abs=0.01)
    s = blur.intensity(u, blur.levels)
    assert torch.allclose(interpolate_levels(s, blur.levels), values, atol=1e-4)
    with pytest.raises(ValueError, match="low <= high"):
        RandomParameter(2.0, 1.0)
    with pytest.raises(ValueError, match="integer"):
        RandomParameter(0.5, 2, integer=True)


class _Declared:
    from lerobot_phantom.transforms.intensity import RandomParameter

    random_parameter = RandomParameter(500.0, 2500.0)
    levels = (0.0, 500.0, 1500.0, 2500.0)


def test_sample_random_intensity_uses_the_declared_distribution_or_the_thirds():
    from lerobot_phantom.transforms.intensity import is_random, sample_random_intensity

    assert (
        is_random("random") and is_random(" RANDOM ") and not is_random((1 / 3, 1.0)) and not is_random(None)
    )
    s = sample_random_intensity(_Declared(), 4000, torch.Generator().manual_seed(1))
    strength = interpolate_levels(s, _Declared.levels)
    assert ((s >= 1 / 3 - 1e-6) & (s <= 1.0)).all()
    # strength uniform on [500, 2500]: half the draws lie below 1500 (s < 2/3)
    assert (strength < 1500).float().mean().item() == pytest.approx(0.5, abs=0.03)
    plain = sample_random_intensity(object(), 4000, torch.Generator().manual_seed(1))
    assert plain.min().item() >= 1 / 3 - 1e-6 and plain.max().item() <= 1.0
    with pytest.raises(ValueError, match="Generator"):
        sample_random_intensity(_Declared(), 3, None)
