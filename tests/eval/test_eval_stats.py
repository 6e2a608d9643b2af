"""Wilson intervals and the exact paired test, against published values and scipy's independent implementation
(scipy comes with lerobot[aloha] through dm_control; those comparisons skip where it is absent)."""

import pytest

from lerobot_phantom.eval.stats import binomial_two_sided_p, mcnemar_exact, wilson_interval

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


def binomtest(*args):
    return pytest.importorskip("scipy.stats").binomtest(*args)


def test_wilson_matches_scipy_everywhere():
    for episodes in (1, 2, 7, 20, 50, 500):
        for successes in range(episodes + 1):
            reference = binomtest(successes, episodes).proportion_ci(confidence_level=0.95, method="wilson")
            low, high = wilson_interval(successes, episodes)
            assert (low, high) == pytest.approx((reference.low, reference.high), abs=1e-12)
            assert 0.0 <= low <= successes / episodes <= high <= 1.0
    reference = binomtest(3, 10).proportion_ci(confidence_level=0.9, method="wilson")
    assert wilson_interval(3, 10, confidence=0.9) == pytest.approx((reference.low, reference.high), abs=1e-12)


def test_wilson_rejects_bad_counts():
    with pytest.raises(ValueError, match="episodes > 0"):
        wilson_interval(0, 0)
    with pytest.raises(ValueError, match="successes must lie"):
        wilson_interval(5, 4)
    with pytest.raises(ValueError, match="confidence"):
        wilson_interval(1, 4, confidence=1.0)


def test_sign_test_matches_scipy():
    for n in range(0, 30):
        for k in range(n + 1):
            expected = 1.0 if n == 0 else binomtest(k, n, 0.5).pvalue
            assert binomial_two_sided_p(k, n) == pytest.approx(expected, rel=1e-12)


def test_mcnemar_counts_discordant_pairs_only():
    before = [True, True, False, False, False, False, False, True]
    after = [True, False, True, True, True, True, True, True]
    test = mcnemar_exact(before, after)
    assert (test.pairs, test.both, test.gained, test.lost) == (8, 2, 5, 1)
    assert test.delta == pytest.approx(4 / 8)
    assert test.p_value == pytest.approx(binomtest(5, 6, 0.5).pvalue)
    assert mcnemar_exact([True] * 5, [True] * 5).p_value == 1.0
    with pytest.raises(ValueError, match="matched episodes"):
        mcnemar_exact([True], [True, False])
