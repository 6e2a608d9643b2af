"""Two runs of ``session84/dwell_share.py`` on the same draws, compared: per case and camera tone curve, the range of
the dwell share in each run and the draws whose verdict (``DWELL_SHARE_FLOOR``) changed. The newer run's labels name
the tone (``(srgb)``); the older's may not, so draws are paired by case, master seed and model.

Usage: ``python docs/bench/session85/dwell_compare.py OLD.txt NEW.txt``
"""

from __future__ import annotations

import re
import sys
from collections import defaultdict

LINE = re.compile(
    r"^(?P<case>\S+) master (?P<master>\d+)(?: \((?P<tone>\w+)\))? (?P<model>\S+): path .* dwell (?P<dwell>[\d.]+) "
    r"\((?P<verdict>\w+)\)"
)


def read(path: str) -> dict[tuple[str, str, str], tuple[str | None, float, str]]:
    """(case, master, model) -> (tone, dwell share, verdict) of every fit line in ``path``."""
    rows = {}
    with open(path) as lines:
        for line in lines:
            match = LINE.match(line)
            if match:
                key = (match["case"], match["master"], match["model"])
                rows[key] = (match["tone"], float(match["dwell"]), match["verdict"])
    return rows


def main() -> None:
    old, new = read(sys.argv[1]), read(sys.argv[2])
    missing = sorted(set(new) ^ set(old))
    if missing:
        raise SystemExit(f"the runs fit different draws: {missing[:4]} ...")
    groups = defaultdict(list)
    for key, (tone, dwell, _verdict) in new.items():
        groups[(key[0], tone)].append((old[key][1], dwell))
    print("case, tone: fits, dwell range in OLD -> in NEW")
    for (case, tone), pairs in sorted(groups.items()):
        before, after = zip(*pairs, strict=True)
        print(
            f"{case} {tone}: {len(pairs)} fits, {min(before):.3f}-{max(before):.3f} -> {min(after):.3f}-{max(after):.3f}"
        )
    print("verdicts changed (case master model: OLD -> NEW):")
    for key in sorted(new):
        if new[key][2] != old[key][2]:
            print(
                f"{' '.join(key)} ({new[key][0]}): {old[key][1]:.3f} {old[key][2]} -> {new[key][1]:.3f} {new[key][2]}"
            )
    for case in sorted({key[0] for key in new}):
        flipped = sum(1 for key in new if key[0] == case and new[key][2] != old[key][2])
        turns = sum(1 for key in new if key[0] == case and new[key][2] == "turns")
        print(
            f"{case}: {turns} of {sum(1 for key in new if key[0] == case)} fits turn in NEW ({flipped} changed)"
        )


if __name__ == "__main__":
    main()
