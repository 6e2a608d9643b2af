"""Counts of ``shot_noise`` named before and after, by case kind and by case, over noise_ab_probe.py outputs.

Usage: ``python docs/bench/session50/summarise_noise_ab.py OUTPUT...``
"""

import collections
import sys
from pathlib import Path

by_kind, by_case = collections.Counter(), collections.Counter()
for path in sys.argv[1:]:
    for line in Path(path).read_text().splitlines():
        fields = line.split()
        case, kind, before, after = fields[1], fields[2], fields[4] == "named", fields[6] == "named"
        for counter, key in ((by_kind, kind), (by_case, case)):
            counter[key, "cases"] += 1
            counter[key, "before"] += before
            counter[key, "after"] += after
for title, counter in (("kind", by_kind), ("case", by_case)):
    for key in sorted({k for k, _ in counter}):
        print(
            f"{title} {key:30s} shot_noise named before {counter[key, 'before']:2d} after {counter[key, 'after']:2d} "
            f"of {counter[key, 'cases']:2d}"
        )
