"""camsim cases run by ``camsim_core_batch.sh`` with two packages on the same master seeds, side by side: each case's
verdict by the test's rules (``camsim_named_causes.case_results``), named causes and written held-out RMSE, and
the counts over the cases both sides ran (session 96).

Usage: ``[CAMSIM_CCM=1] CAMSIM_CASES=... PYTHONPATH=. python docs/bench/session96/case_ab.py BEFORE_OUT AFTER_OUT``
(the batch's CAMSIM_CASES and CAMSIM_CCM).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from camsim_named_causes import case_results


def side(out: str) -> dict[tuple[str, str], tuple[dict, dict]]:
    return {
        (seed, case.name): (report, judged) for seed, _sim, case, report, judged in case_results(Path(out))
    }


def main() -> None:
    before, after = side(sys.argv[1]), side(sys.argv[2])
    both = sorted(before.keys() & after.keys())
    counts = {"before passed": 0, "after passed": 0, "same named": 0, "after lower held-out": 0, "equal": 0}
    for key in both:
        (old_report, old), (new_report, new) = before[key], after[key]
        old_rmse, new_rmse = (r["extended"]["heldout_rmse"] for r in (old_report, new_report))
        counts["before passed"] += old["passed"]
        counts["after passed"] += new["passed"]
        counts["same named"] += old["named"] == new["named"]
        counts["after lower held-out"] += new_rmse < old_rmse
        counts["equal"] += new_rmse == old_rmse
        print(
            f"{key[0]:>11} {key[1]:26s} {old['camera'].tone:6s} {'OK  ' if old['passed'] else 'MISS'} -> "
            f"{'OK  ' if new['passed'] else 'MISS'} named {sorted(old['named'])} -> {sorted(new['named'])}; "
            f"unplanted {len(old['unplanted'])} -> {len(new['unplanted'])}; held-out {old_rmse:.2f} -> {new_rmse:.2f}"
        )
    print(f"{len(both)} cases on both sides: " + ", ".join(f"{k} {v}" for k, v in counts.items()))


if __name__ == "__main__":
    main()
