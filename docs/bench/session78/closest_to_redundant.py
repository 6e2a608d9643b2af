"""The written effects of camsim reports whose selected model without them comes nearest to rule 2's redundancy
bound (``identify.Redundancy``: the interval's high end under 1 + margin / 2), lowest high end first.

Usage: ``python docs/bench/session78/closest_to_redundant.py COUNT OUT...`` (each OUT in
``session64/run_camsim_case.py``'s layout)."""

from __future__ import annotations

import json
import sys
from pathlib import Path


def main() -> None:
    count, outs = int(sys.argv[1]), [Path(p) for p in sys.argv[2:]]
    rows = []
    for out in outs:
        for path in sorted(out.glob("bt_*/camsim0/*/out/report.json")):
            report = json.loads(path.read_text())
            margin = report["gain"]["selection_margin"]
            for result in report["identification"]:
                ratio = result.get("ratio_without")
                if ratio and result["identified"]:
                    seed, case = path.parts[-5][3:], path.parts[-3]
                    rows.append(
                        (ratio["high"], ratio["estimate"], ratio["low"], result["effect"], case, seed, margin)
                    )
    rows.sort()
    print(f"{len(rows)} written effects scored without; the {count} nearest the bound:")
    for high, estimate, low, effect, case, seed, margin in rows[:count]:
        print(
            f"{seed} {case} {effect}: {estimate:.4f} [{low:.4f}, {high:.4f}]; bound {1 + margin / 2:g}, "
            f"the whole margin's {1 + margin:g}"
        )


if __name__ == "__main__":
    main()
