"""Per arm of ``dark_frame_ab.py``'s logs: the draws whose planted causes are all named (the test's verdict), the
glare named, its fitted exponent's distance from the planted one (draws naming it), the median cross-validated
score of linear light alone and the glare's median share under it (the selection's first step), and the median held-out RMSE; then each arm
against ``plain`` draw by draw.

Usage: ``python docs/bench/session80/dark_frame_summary.py LOG...``
"""

from __future__ import annotations

import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

LINE = re.compile(
    r"^(?P<seed>\d+) (?P<arm>\w+): named (?P<named>\[.*?\]) (?P<verdict>pass|MISS); held-out RMSE base \S+ "
    r"extended (?P<heldout>\S+); CV linear light (?P<linear>\S+), with the glare "
    r"(?:(?P<glare>\S+) \((?P<share>\S+)%\)|not scored); "
    r"(?:level \S+ exponent (?P<exponent>\S+)|no glare) \(planted exponent (?P<planted>\S+)\)"
)


def main() -> None:
    runs: dict[str, dict[int, dict]] = defaultdict(dict)
    for path in sys.argv[1:]:
        for line in Path(path).read_text().splitlines():
            match = LINE.match(line)
            if match:
                runs[match["arm"]][int(match["seed"])] = match.groupdict()
    for arm, draws in runs.items():
        named = [d for d in draws.values() if d["exponent"] is not None]
        scored = [d for d in draws.values() if d["share"] is not None]
        errors = [abs(float(d["exponent"]) - float(d["planted"])) for d in named]
        print(
            f"{arm}: {len(draws)} draws; planted causes named on {sum(d['verdict'] == 'pass' for d in draws.values())}, "
            f"the glare on {len(named)}; its exponent's distance from the planted one median "
            f"{np.median(errors) if errors else float('nan'):.2f} (within 0.3 on {sum(e <= 0.3 for e in errors)}); "
            f"CV linear light alone median {np.median([float(d['linear']) for d in draws.values()]):.3f}, "
            f"the glare's share under it median {np.median([float(d['share']) for d in scored]):+.1f}% "
            f"({len(scored)} draws scored it there); "
            f"held-out RMSE median {np.median([float(d['heldout']) for d in draws.values()]):.3f}"
        )
    if "plain" not in runs:
        return
    for arm, draws in runs.items():
        if arm == "plain":
            continue
        common = sorted(set(draws) & set(runs["plain"]))
        lower = sum(float(draws[d]["heldout"]) < float(runs["plain"][d]["heldout"]) for d in common)
        print(f"\n{arm} against plain, draw by draw ({len(common)} draws; held-out RMSE lower on {lower}):")
        for seed in common:
            a, b = runs["plain"][seed], draws[seed]
            print(
                f"  {seed}: verdict {a['verdict']} -> {b['verdict']}; CV linear light {a['linear']} -> {b['linear']}; "
                f"glare share {a['share'] or '-'}% -> {b['share'] or '-'}%; exponent {a['exponent'] or '-'} -> "
                f"{b['exponent'] or '-'} (planted {a['planted']}); held-out {a['heldout']} -> {b['heldout']}"
            )


if __name__ == "__main__":
    main()
