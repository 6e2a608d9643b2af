"""Two runs of camsim cases side by side (``camsim_core_batch.sh`` layout: ``OUT/bt_SEED/camsim0/CASE``), case by
case over the cases AFTER holds: the named causes, the selection steps' models and the written model's held-out RMSE.

Usage: ``python docs/bench/session78/same_named_and_steps.py BEFORE_OUT AFTER_OUT``"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def summary(report: dict) -> tuple[list[str], list[list[str]], float]:
    named = sorted(r["effect"] for r in report["identification"] if r["identified"])
    return named, [s["effects"] for s in report["selection"]["steps"]], report["extended"]["heldout_rmse"]


def main() -> None:
    before, after = Path(sys.argv[1]), Path(sys.argv[2])
    same = total = 0
    for path in sorted(after.glob("bt_*/camsim0/*/out/report.json")):
        other = before / path.relative_to(after)
        (named_b, steps_b, rmse_b), (named_a, steps_a, rmse_a) = (
            summary(json.loads(p.read_text())) for p in (other, path)
        )
        alike = named_a == named_b and steps_a == steps_b and f"{rmse_a:.3f}" == f"{rmse_b:.3f}"
        same, total = same + alike, total + 1
        seed, case = path.parts[-5][3:], path.parts[-3]
        print(
            f"{seed} {case}: {'same' if alike else 'DIFFERENT'}; named {named_b} -> {named_a}; "
            f"held-out {rmse_b:.3f} -> {rmse_a:.3f}"
        )
    print(f"{same} of {total} cases the same (named causes, steps, held-out RMSE to 3 decimals)")


if __name__ == "__main__":
    main()
