"""camsim's blinding cases at two packages on the same master seeds (two ``camsim_core_batch.sh`` output folders):
per seed and case, the causes each names (the planted ones from the case's definition) and the written model's
held-out RMSE, predictive (the report's figure) and expected over the frames' unknown exposures
(``heldout_expected_rmse``, the figure an unseen auto-exposed frame gets); then, per case, how many draws name every
planted cause at each package and how the expected error moved.

Usage: ``PYTHONPATH=.:tests/calibration:tests CAMSIM_SEED=0 python docs/bench/session91/blinding_matrix_ab.py
OLD_OUT NEW_OUT`` (``CAMSIM_SEED`` only lets the test module import; the cases' definitions do not depend on it).
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict
from pathlib import Path

from test_independent_sim import CASE_BY_NAME


def reports(out: Path) -> dict[tuple[str, str], dict]:
    found = {}
    for path in sorted(out.glob("bt_*/camsim0/*/out/report.json")):
        seed, case = path.parents[3].name.removeprefix("bt_"), path.parents[1].name
        found[(seed, case)] = json.loads(path.read_text())
    return found


def named(report: dict) -> list[str]:
    return sorted(x["effect"] for x in report["identification"] if x["identified"])


def main() -> None:
    old, new = (reports(Path(p)) for p in sys.argv[1:3])
    tally = defaultdict(
        lambda: [0, 0, 0, [], []]
    )  # draws, old all planted, new all planted, expected old/new
    for key in sorted(set(old) & set(new), key=lambda k: (k[1], k[0])):
        seed, case = key
        planted = set(CASE_BY_NAME[case].planted)
        row = tally[case]
        row[0] += 1
        figures = []
        for column, report in ((1, old[key]), (2, new[key])):
            causes = named(report)
            row[column] += planted <= set(causes)
            row[column + 2].append(report["extended"]["heldout_expected_rmse"])
            figures.append(
                f"{causes} predictive {report['extended']['heldout_rmse']:.2f} expected "
                f"{report['extended']['heldout_expected_rmse']:.2f}"
            )
        print(f"{case} {seed}: planted {sorted(planted)}\n  old {figures[0]}\n  new {figures[1]}")
    print()
    for case, (draws, old_all, new_all, expected_old, expected_new) in sorted(tally.items()):
        moved = [n - o for o, n in zip(expected_old, expected_new, strict=True)]
        lower, higher = sum(m < -0.005 for m in moved), sum(m > 0.005 for m in moved)
        print(
            f"{case}: every planted cause named on {old_all} of {draws} (old), {new_all} of {draws} (new); expected "
            f"held-out RMSE lower on {lower} of {draws}, higher on {higher} (by more than 0.005), old "
            f"{min(expected_old):.2f}-{max(expected_old):.2f}, new {min(expected_new):.2f}-{max(expected_new):.2f}"
        )


if __name__ == "__main__":
    main()
