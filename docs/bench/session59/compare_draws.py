"""Two ``truncation_draws.py`` outputs on the same draws, per case: ``python compare_draws.py BEFORE AFTER``.

Prints, per case: draws, passes before and after (the test's rules), the median held-out RMSE of the written model
before and after, and the draws whose held-out RMSE moved by more than 1% (better / worse), the null cases' largest cross-validated gain
of an extension (the first selection step's), then every draw whose verdict or named causes changed.
"""

import sys
from collections import defaultdict
from pathlib import Path

import numpy as np


def read(path: str) -> dict[tuple[str, str], list[str]]:
    rows = {}
    for line in Path(path).read_text().splitlines():
        if line.startswith("case |"):
            continue
        fields = [f.strip() for f in line.split("|")]
        rows[(fields[0], fields[1])] = fields
    return rows


def main() -> None:
    before, after = read(sys.argv[1]), read(sys.argv[2])
    by_case = defaultdict(list)
    for key in before:
        if key in after:
            by_case[key[0]].append((before[key], after[key]))
    print(
        "case | draws | pass before | pass after | median held-out before | after | better | worse (by > 1%)"
    )
    changed = []
    for case, rows in by_case.items():
        held = np.array([[float(b[6].split("->")[1]), float(a[6].split("->")[1])] for b, a in rows])
        ratio = held[:, 1] / held[:, 0]
        print(
            f"{case} | {len(rows)} | {sum(b[4] == 'pass' for b, _ in rows)} | {sum(a[4] == 'pass' for _, a in rows)} | "
            f"{np.median(held[:, 0]):.3f} | {np.median(held[:, 1]):.3f} | {int((ratio < 0.99).sum())} | "
            f"{int((ratio > 1.01).sum())}"
        )
        changed += [(b, a) for b, a in rows if b[3:5] != a[3:5]]
    for label, side in (("before", 0), ("after", 1)):
        gains = [
            1 - float(pair[side][5].split("->")[1]) / float(pair[side][5].split("->")[0])
            for pair in by_case.get("truncation_null", [])
        ]
        if gains:
            print(f"nulls' largest cross-validated gain of an extension, {label}: {max(gains):.1%}")
    for b, a in changed:
        print(
            f"changed: {b[0]} {b[1]}: {b[3]} {b[4]} -> {a[3]} {a[4]} "
            f"(held-out, base -> written: before {b[6]}, after {a[6]})"
        )


if __name__ == "__main__":
    main()
