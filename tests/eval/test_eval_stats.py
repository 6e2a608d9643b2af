"""Wilson intervals and the exact McNemar test, against published values and exact binomial arithmetic."""

from math import comb

import pytest

from lerobot_phantom.eval.stats import mcnemar_exact, wilson_interval

# Newcombe (1998), "Two-sided confidence intervals for the single proportion", Stat. Med. 17:857-872, Table I,
# method 3 (Wilson score interval without continuity correction), 95 %.
NEWCOMBE = [
    (81, 263, 0.2553, 0.3662),
    (15, 148, 0.0624, 0.1605),
    (0, 20, 0.0000, 0.1611),
    (1, 29, 0.0061, 0.1718),
    (29, 29, 0.8830, 1.0000),
]


@pytest.mark.parametrize(("successes", "episodes", "low", "high"), NEWCOMBE)
def test_wilson_matches_published_values(successes, episodes, low, high):
    got_low, got_high = wilson_interval(successes, episodes)
    assert got_low == pytest.approx(low, abs=5e-5)
    assert got_high == pytest.approx(high, abs=5e-5)


def test_wilson_narrows_with_lower_confidence_and_contains_the_estimate():
    wide, narrow = wilson_interval(3, 10, confidence=0.95), wilson_interval(3, 10, confidence=0.9)
    assert wide[0] < narrow[0] < 0.3 < narrow[1] < wide[1]


def test_wilson_rejects_bad_counts():
    with pytest.raises(ValueError, match="episodes > 0"):
        wilson_interval(0, 0)
    with pytest.raises(ValueError, match="successes must lie"):
        wilson_interval(5, 4)
    with pytest.raises(ValueError, match="confidence"):
        wilson_interval(1, 4, confidence=1.0)


def exact_two_sided(k: int, n: int) -> float:
    """The sign test by hand: twice the smaller binomial(n, 1/2) tail, capped at 1."""
    tail = min(k, n - k)
    return min(1.0, 2 * sum(comb(n, i) for i in range(tail + 1)) / 2**n)


@pytest.mark.parametrize(("gained", "lost"), [(5, 1), (0, 10), (1, 9), (3, 3), (12, 2)])
def test_mcnemar_p_value_is_the_exact_sign_test_on_discordant_pairs(gained, lost):
    concordant = 4  # pairs that agree carry no information: adding them must not change p
    before = [False] * gained + [True] * lost + [True] * concordant
    after = [True] * gained + [False] * lost + [True] * concordant
    test = mcnemar_exact(before, after)
    assert test.p_value == pytest.approx(exact_two_sided(gained, gained + lost), rel=1e-12)


def test_mcnemar_counts_discordant_pairs_only():
    before = [True, True, False, False, False, False, False, True]
    after = [True, False, True, True, True, True, True, True]
    test = mcnemar_exact(before, after)
    assert (test.pairs, test.both, test.gained, test.lost) == (8, 2, 5, 1)
    assert test.delta == pytest.approx(4 / 8)
    assert test.p_value == pytest.approx(14 / 64)  # 2 * (C(6,0) + C(6,1)) / 2**6
    assert mcnemar_exact([True] * 5, [True] * 5).p_value == 1.0
    with pytest.raises(ValueError, match="matched episodes"):
        mcnemar_exact([True], [True, False])
