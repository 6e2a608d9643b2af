"""How much longer the tests two suite runs both ran took in the second: the ratio of each test's time (setup + call +
teardown) over the tests of at least ``MIN_S`` seconds in both.

    python docs/bench/session60/same_tests_two_runs.py FIRST_LOG SECOND_LOG
"""

import re
import sys
from collections import Counter
from pathlib import Path

import numpy as np

DURATION = re.compile(r"^([\d.]+)s (?:setup|call|teardown)\s+(.+?)@(\S+)$")
MIN_S = 5.0


def times(path: str) -> Counter:
    found: Counter = Counter()
    for line in Path(path).read_text().splitlines():
        match = DURATION.match(line.strip())
        if match:
            found[match.group(2).strip()] += float(match.group(1))
    return found


def main() -> None:
    first, second = times(sys.argv[1]), times(sys.argv[2])
    both = sorted(t for t in first.keys() & second.keys() if min(first[t], second[t]) >= MIN_S)
    ratios = np.array([second[t] / first[t] for t in both])
    print(
        f"{len(both)} tests of at least {MIN_S:g} s in both runs, second / first: median {np.median(ratios):.2f}, "
        f"quartiles {np.percentile(ratios, 25):.2f}-{np.percentile(ratios, 75):.2f}, "
        f"range {ratios.min():.2f}-{ratios.max():.2f} (tests that draw fresh seeds did other work in each run)"
    )
    for t in sorted(both, key=lambda t: -first[t])[:8]:
        print(f"  {first[t]:7.1f} -> {second[t]:7.1f} s  {t[:110]}")


if __name__ == "__main__":
    main()
