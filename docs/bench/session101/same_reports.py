"""Two camsim batch outputs (``OUTDIR/bt_SEED/camsim0/CASE/out/report.json``) compared key by key, per case both hold:
the JSON paths whose values differ, leaving out the keys named (a field one side does not write, the criterion text)
and the pairs' directory.

usage: python docs/bench/session101/same_reports.py BEFORE_OUT AFTER_OUT [KEY...]
"""

import json
import sys
from pathlib import Path


def differences(a, b, path: str, ignored: set[str]) -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        keys = (a.keys() | b.keys()) - ignored
        return [d for k in sorted(keys) for d in differences(a.get(k), b.get(k), f"{path}/{k}", ignored)]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in differences(x, y, f"{path}/{i}", ignored)
        ]
    return [] if a == b else [path]


before, after, ignored = Path(sys.argv[1]), Path(sys.argv[2]), {"criterion", *sys.argv[3:]}
same = 0
for path in sorted(before.rglob("out/report.json")):
    other = after / path.relative_to(before)
    if not other.exists():
        continue
    a, b = json.loads(path.read_text()), json.loads(other.read_text())
    found = [d for d in differences(a, b, "", ignored) if d != "/input/path"]
    case = path.parent.parent.name
    if found:
        print(f"{case} differs at {len(found)} paths, first: {found[:4]}")
    else:
        same += 1
print(f"{same} cases the same key by key (leaving out {sorted(ignored)} and /input/path)")
