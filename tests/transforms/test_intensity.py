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
