"""The laser strip's camsim reports at two packages, case by case: named effects and the written model's held-out
figures (predictive, registered at each frame's best pulse phase, expected over the phase), from each run's
``report.json``. OLD: a ``camsim_core_batch.sh`` output (``OLD/bt_SEED/camsim0/CASE``); NEW: folders written by
``run_camsim_case.py`` (``NEW/bt_SEED/camsim0/CASE``), one or more.

Usage: ``python docs/bench/session87/strip_compare.py OLD NEW...``
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def reports(root: Path) -> dict[tuple[str, str], dict]:
    found = {}
    for path in sorted(root.glob("bt_*/camsim0/strip_*/out/report.json")):
        seed, case = path.parts[-5][3:], path.parts[-3]
        found[(case, seed)] = json.loads(path.read_text())
    return found


def line(report: dict) -> str:
    ext = report["extended"]
    labels = {
        "heldout_rmse": "predictive",
        "heldout_registered_rmse": "registered",
        "heldout_expected_rmse": "expected",
    }
    figures = ", ".join(f"{label} {ext[key]:.3f}" for key, label in labels.items() if key in ext)
    return f"named {sorted(ext['effects'])}; {figures}"


def main() -> None:
    old = reports(Path(sys.argv[1]))
    new = {k: v for root in sys.argv[2:] for k, v in reports(Path(root)).items()}
    for key in sorted(new):
        case, seed = key
        print(f"{case:22s} {seed:>10s} OLD {line(old[key]) if key in old else '(none)'}")
        print(f"{'':22s} {'':>10s} NEW {line(new[key])}")


if __name__ == "__main__":
    main()
