"""Honest uncertainty for success counts: Wilson score intervals and exact paired tests on matched seeds.

Pure Python (``math``/``statistics``): these are a few lines each and run inside report loops, so they do not pull
in scipy; the tests check them against scipy's independent implementations.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from statistics import NormalDist


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
    z = NormalDist().inv_cdf(0.5 + confidence / 2.0)
    p = successes / episodes
    denom = 1.0 + z * z / episodes
    centre = (p + z * z / (2.0 * episodes)) / denom
    half = z * math.sqrt(p * (1.0 - p) / episodes + z * z / (4.0 * episodes * episodes)) / denom
    # Clamp rounding noise only; the exact interval touches 0 or 1 when successes is 0 or n.
    low = 0.0 if successes == 0 else max(0.0, centre - half)
    high = 1.0 if successes == episodes else min(1.0, centre + half)
    return low, high


def binomial_two_sided_p(k: int, n: int) -> float:
    """Exact two-sided p-value of ``k`` successes in ``n`` fair coin flips (the sign test)."""
    if n < 0 or not 0 <= k <= n:
        raise ValueError(f"need 0 <= k <= n, got k={k}, n={n}")
    if n == 0:
        return 1.0
    tail = min(k, n - k)
    p = 2.0 * sum(math.comb(n, i) for i in range(tail + 1)) / 2.0**n
    return min(1.0, p)


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
    """Exact McNemar (= sign test on discordant pairs) for two success sequences over the same episodes."""
    before, after = [bool(b) for b in before], [bool(a) for a in after]
    if len(before) != len(after):
        raise ValueError(
            f"paired test needs matched episodes, got {len(before)} before and {len(after)} after"
        )
    gained = sum(1 for b, a in zip(before, after, strict=True) if a and not b)
    lost = sum(1 for b, a in zip(before, after, strict=True) if b and not a)
    both = sum(1 for b, a in zip(before, after, strict=True) if a and b)
    return PairedTest(
        pairs=len(before),
        both=both,
        gained=gained,
        lost=lost,
        p_value=binomial_two_sided_p(gained, gained + lost),
    )
