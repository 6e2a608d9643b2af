"""Counts over ``dwell_lowpass.py`` outputs: per case and read (as read, low-passed at each sigma), the draws whose
dwell share reaches each floor, and the range. Usage: ``python docs/bench/session98/dwell_counts.py FLOOR[,FLOOR...]
OUTPUT...``."""

from __future__ import annotations

import re
import sys
from collections import defaultdict

LINE = re.compile(r"^(?P<case>\S+) master (?P<master>\d+) \((?P<tone>\w+)\): dwell share (?P<reads>.*)$")
READ = re.compile(r"(?P<label>as read|low-passed [\d.]+ px) (?P<share>[\d.]+)")


def main() -> None:
    floors = [float(f) for f in sys.argv[1].split(",")]
    shares: dict[tuple[str, str], dict[str, float]] = defaultdict(dict)
    for path in sys.argv[2:]:
        with open(path) as lines:
            for line in lines:
                match = LINE.match(line.strip())
                if match:
                    for read in READ.finditer(match["reads"]):
                        shares[(match["case"], read["label"])][match["master"]] = float(read["share"])
    for (case, label), by_draw in sorted(shares.items()):
        values = sorted(by_draw.values())
        counts = ", ".join(f">= {f:g}: {sum(v >= f for v in values)}" for f in floors)
        print(f"{case} {label}: {len(values)} draws, {values[0]:.3f}-{values[-1]:.3f}; reaching {counts}")


if __name__ == "__main__":
    main()
