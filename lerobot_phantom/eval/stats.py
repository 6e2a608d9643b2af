"""Honest uncertainty for success counts: Wilson score intervals and the exact McNemar test on matched seeds.

Both are scipy's (``scipy.stats.binomtest``); this module adds the argument checks with clear messages and the
paired bookkeeping (which episodes gained or lost success).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from scipy.stats import binomtest


def wilson_interval(successes: int, episodes: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion (no continuity correction).

    Unlike the normal (Wald) interval it stays inside [0, 1] and is not degenerate at 0 or n successes, which is
    the usual case for TSR (an expert at 100 %, a blinded policy at 0 %).
    """
    if episodes <= 0:
        raise ValueError(f"a Wilson interval needs episodes > 0, got {episodes}")
    if not 0 <= successes <= episodes:
        raise ValueError(f"successes must lie in [0, episodes={episodes}], got {successes}")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must lie in (0, 1), got {confidence}")
    interval = binomtest(int(successes), int(episodes)).proportion_ci(
        confidence_level=confidence, method="wilson"
    )
    return float(interval.low), float(interval.high)


@dataclass(frozen=True)
class PairedTest:
    """Exact McNemar test on matched episodes: only discordant pairs carry information."""

    pairs: int
    both: int  # success before and after
    gained: int  # failure before, success after
    lost: int  # success before, failure after
    p_value: float

    @property
    def delta(self) -> float:
        """Paired TSR difference (after - before), in [-1, 1]."""
        return (self.gained - self.lost) / self.pairs if self.pairs else 0.0


def mcnemar_exact(before: Iterable[bool], after: Iterable[bool]) -> PairedTest:
    """Exact McNemar test for two success sequences over the same episodes: the two-sided exact binomial test of
    ``gained`` out of the ``gained + lost`` discordant pairs against 1/2 (p = 1 with no discordant pair)."""
    before, after = [bool(b) for b in before], [bool(a) for a in after]
    if len(before) != len(after):
        raise ValueError(
            f"paired test needs matched episodes, got {len(before)} before and {len(after)} after"
        )
    gained = sum(1 for b, a in zip(before, after, strict=True) if a and not b)
    lost = sum(1 for b, a in zip(before, after, strict=True) if b and not a)
    both = sum(1 for b, a in zip(before, after, strict=True) if a and b)
    discordant = gained + lost
    p_value = 1.0 if discordant == 0 else float(binomtest(gained, discordant, 0.5).pvalue)
    return PairedTest(pairs=len(before), both=both, gained=gained, lost=lost, p_value=p_value)
