"""Long calibration checks are sampled: each run of the suite runs a seeded share of them.

A test marked ``sampled`` runs a whole calibration on generated or measured data and judges it (40 s to 6 min each on
two cores). The 34 of them and the independent simulator's cases took 77% of the suite's test time in session 59's
run (5114 of 6684 s, ``docs/bench/session60/suite_abac8ef_parts.txt``; 58.5 min on two workers, against the 30
the project allows its suite). So each run draws a share of every file's sampled tests (and of the simulator's cases,
by kind), afresh from ``SAMPLED_SEED``: over runs every check runs, and each run still meets fresh draws.
``SAMPLED_SHARE=all`` runs every one (what a change to the calibration is checked with before it is merged); a test
named on the command line by its node id always runs.
"""

from __future__ import annotations

import math
import os
import zlib
from collections.abc import Mapping, Sequence

import numpy as np

SHARE_VARIABLE = "SAMPLED_SHARE"
SEED_VARIABLE = "SAMPLED_SEED"
# a tenth: at 0.2 the suite took 32.9 min (session 60, docs/bench/session60/suite_339e1f2_durations.log), 1975 s
# of its test time in the tests every run runs; a tenth of the sampled ones adds about 600 s on that machine
DEFAULT_SHARE = 0.1


def share_from_env(environ: Mapping[str, str] = os.environ) -> float:
    """The share of sampled tests a run draws: ``SAMPLED_SHARE`` ("all", or a number in (0, 1]), else the default."""
    value = environ.get(SHARE_VARIABLE, "").strip()
    if not value:
        return DEFAULT_SHARE
    if value == "all":
        return 1.0
    try:
        share = float(value)
    except ValueError:
        share = math.nan
    if not 0.0 < share <= 1.0:
        raise ValueError(
            f"{SHARE_VARIABLE}={value!r}: expected 'all' or a share in (0, 1], e.g. {DEFAULT_SHARE}"
        )
    return share


def group_rng(seed: int, group: str) -> np.random.Generator:
    """The generator of one group's draw (a test file, a kind of case): groups drawn apart, each from the run's seed."""
    return np.random.default_rng([seed, zlib.crc32(group.encode())])


def draw(names: Sequence[str], share: float, rng: np.random.Generator, *, at_least: int = 0) -> list[str]:
    """``share`` of ``names`` on average, in their order: the whole part of ``share * len(names)`` and one more with
    the chance of the fraction left, so a group of three at a fifth runs 0.6 tests a run rather than one or none."""
    expected = share * len(names)
    count = int(expected) + int(rng.random() < expected - int(expected))
    count = min(len(names), max(count, at_least))
    chosen = rng.permutation(len(names))[:count]
    return [names[i] for i in sorted(chosen)]
