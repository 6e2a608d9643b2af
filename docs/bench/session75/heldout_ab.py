"""Held-out RMSE of the written model per case, before and after, from two ``session66/case_summary.py`` outputs
(the same master seeds): the range over the seeds on each side, how many fell or rose, the before/after ratio
and the named causes after. Usage: ``python docs/bench/session75/heldout_ab.py BEFORE.txt AFTER.txt``."""

import re
import sys
from pathlib import Path

LINE = re.compile(r"\S+ (\d+) (\S+): named (\[.*?\]); held-out base ([\d.]+), written ([\d.]+)")


def load(path: str) -> dict[tuple[str, str], tuple[str, float]]:
    rows = {}
    for line in Path(path).read_text().splitlines():
        match = LINE.match(line)
        if match:
            rows[(match[1], match[2])] = (match[3], float(match[5]))
    return rows


def main() -> None:
    before, after = load(sys.argv[1]), load(sys.argv[2])
    for case in sorted({case for _, case in before}):
        keys = sorted(k for k in before if k[1] == case)
        old = [before[k][1] for k in keys]
        new = [after[k][1] for k in keys]
        ratios = [o / n for o, n in zip(old, new, strict=True)]
        print(
            f"{case}: {len(keys)} seeds; written model held-out {min(old):.2f}-{max(old):.2f} -> "
            f"{min(new):.2f}-{max(new):.2f}; lower on {sum(n < o for o, n in zip(old, new, strict=True))}, higher on "
            f"{sum(n > o for o, n in zip(old, new, strict=True))}; before/after {min(ratios):.2f}-{max(ratios):.2f}; "
            f"named after: {sorted({after[k][0] for k in keys})}"
        )


if __name__ == "__main__":
    main()
