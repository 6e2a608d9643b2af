"""Two outputs of ``docs/bench/session65/neighbour_null.py`` on the same seeds, compared per design and ripple: the
width of each table's 90% interval (after over before), verdicts that agree, the largest change of an estimate.

usage: python docs/bench/session66/compare_neighbour_intervals.py BEFORE.txt AFTER.txt
"""

import re
import sys
from pathlib import Path

import numpy as np

LINE = re.compile(
    r"(\w+) ripple ([\d.]+) seed (\d+): correlation ([+-][\d.]+) \[([+-][\d.]+), ([+-][\d.]+)\] reported (\w+)"
)


def parse(path: str) -> dict:
    out = {}
    for line in Path(path).read_text().splitlines():
        if m := LINE.match(line):
            out[m[1], m[2], m[3]] = (float(m[4]), float(m[5]), float(m[6]), m[7])
    return out


def main() -> None:
    before, after = parse(sys.argv[1]), parse(sys.argv[2])
    for design, ripple in sorted({k[:2] for k in before}):
        keys = [k for k in before if k[:2] == (design, ripple)]
        ratio = [(after[k][2] - after[k][1]) / (before[k][2] - before[k][1]) for k in keys]
        print(
            f"{design} ripple {ripple}: interval width after / before, median {np.median(ratio):.3f} "
            f"(range {min(ratio):.3f}-{max(ratio):.3f}); verdicts the same on {sum(before[k][3] == after[k][3] for k in keys)}"
            f" of {len(keys)}; largest change of an estimate {max(abs(before[k][0] - after[k][0]) for k in keys):.3g}"
        )


if __name__ == "__main__":
    main()
