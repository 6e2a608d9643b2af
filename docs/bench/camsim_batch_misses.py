"""Condense ``camsim_core_batch.sh``'s summary.txt: per master seed, the share of effect cases named and each miss.

Usage: ``python docs/bench/camsim_batch_misses.py OUTDIR/summary.txt``. A seed whose >= 90% naming test passed has
no assertion line; it is printed with the test counts instead.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

LINE = re.compile(r"seed (\d+): .*named in (\d+)% of (\d+) cases.*misses: \[(.*)\]; replay")
MISS = re.compile(r'"(\w+): planted (\[[^\]]*\]), named (\[[^\]]*\])')


def main() -> None:
    for line in Path(sys.argv[1]).read_text().splitlines():
        match = LINE.match(line)
        if not match:
            seed = line.split(":")[0]
            counts = re.findall(r"\d+ (?:passed|failed|xfailed|xpassed)", line)
            print(f"{seed}: no miss assertion ({', '.join(counts)})")
            continue
        seed, share, cases, misses = match.groups()
        listed = "; ".join(f"{case} named {named}" for case, _, named in MISS.findall(misses))
        print(f"seed {seed}: {share}% of {cases} effect cases named; misses: {listed}")


if __name__ == "__main__":
    main()
