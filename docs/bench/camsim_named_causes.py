"""Per case of ``camsim_core_batch.sh`` runs: the camera's tone curve, whether the case passed its rule (effect
cases: planted effects named; null cases: base model kept; unexplained cases: nothing invented and the
structure reported, which is printed), the causes named, the unplanted ones (the test's own
``named_causes`` and ``tolerated``), and the held-out RMSE of the written model and of the base.

Usage: ``CAMSIM_CASES=... python docs/bench/camsim_named_causes.py OUTDIR...`` from the repository root (the same
``CAMSIM_CASES`` as the batch; unset, ``core``, the batch's default). Cases whose ``report.json`` is missing (a run still going) are skipped. With
``CAMSIM_WITHOUT_IMPLIED=1`` the causes that an identified form implies (``Effect.implies``, since session 22) are
taken out of each report first: how the same fits were named before (the implication adds findings and changes
no fit).
"""

from __future__ import annotations

import importlib
import json
import os
import sys
from collections.abc import Iterator
from pathlib import Path

os.environ.setdefault("CAMSIM_CASES", "core")  # camsim_core_batch.sh's default
sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports


def without_implied(report: dict) -> dict:
    """The report without the causes implied by an identified form (their identification entries and findings)."""
    implied = {r["effect"] for r in report["identification"] if r.get("implied_by")}
    return {
        **report,
        "identification": [r for r in report["identification"] if not r.get("implied_by")],
        "findings": [f for f in report["findings"] if f["effect"] not in implied],
    }


def case_results(out: Path, skip_missing: bool = True) -> Iterator[tuple[str, object, object, dict, dict]]:
    """(master seed, the test module for it, case, report, judged) for every case a batch under ``out`` selected;
    ``judged`` holds the camera, the causes named, the unplanted ones and whether the case passed its rule."""
    for folder in sorted(Path(out).glob("bt_*")):
        seed = folder.name.removeprefix("bt_")
        os.environ["CAMSIM_SEED"] = seed
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        for name in sim.SELECTED:
            path = folder / "camsim0" / name / "out" / "report.json"
            if skip_missing and not path.exists():
                continue
            report, case = json.loads(path.read_text()), sim.CASE_BY_NAME[name]
            if os.environ.get("CAMSIM_WITHOUT_IMPLIED"):
                report = without_implied(report)
            camera = sim.case_camera(case)[2]
            named = sim.named_causes(report)
            allowed = sim.tolerated(case, camera)
            if case.kind == "effect":
                passed = case.planted <= named
            elif case.kind == "unexplained":  # the test's rule: nothing invented, and the structure reported
                passed = not named - allowed and bool(sim.unexplained_structure(report))
            else:
                passed = not report["extended"]["effects"]
            judged = {
                "camera": camera,
                "named": named,
                "unplanted": named - case.planted - allowed,
                "passed": passed,
            }
            yield seed, sim, case, report, judged


def main() -> None:
    for out in sys.argv[1:]:
        for seed, sim, case, report, judged in case_results(Path(out)):
            print(
                f"{seed:>11} {case.name:24s} {judged['camera'].tone:6s} "
                f"{'OK  ' if judged['passed'] else 'MISS'} named={sorted(judged['named'])} "
                f"unplanted={sorted(judged['unplanted'])} "
                f"held-out {report['extended']['heldout_rmse']:.2f} base {report['base']['heldout_rmse']:.2f}"
                + (f" structure: {sim.unexplained_structure(report)}" if case.kind == "unexplained" else "")
            )


if __name__ == "__main__":
    main()
