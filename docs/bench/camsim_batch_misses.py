"""Count, per master seed of a ``camsim_core_batch.sh`` run, the effect cases whose planted effects were named.

Usage: ``PYTHONPATH=. python docs/bench/camsim_batch_misses.py OUTDIR`` from the repository root. Reads every case's
``report.json`` that the batch kept under ``OUTDIR/bt_SEED`` and applies the naming test's own rule
(``test_independent_sim.named_causes``) to the cases that master seed selected (``CAMSIM_CASES`` as in the batch),
so seeds whose >= 90% test passed are counted too; also the effect cases naming more than one unplanted cause and
the null cases that gained an effect (what the case tests assert).
"""

from __future__ import annotations

import importlib
import json
import os
import sys
from pathlib import Path

sys.path.insert(0, "tests/calibration")


def main() -> None:
    out = Path(sys.argv[1])
    for folder in sorted(out.glob("bt_*")):
        seed = folder.name.removeprefix("bt_")
        os.environ["CAMSIM_SEED"] = seed
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        effect_cases = [sim.CASE_BY_NAME[n] for n in sim.SELECTED if sim.CASE_BY_NAME[n].kind == "effect"]
        null_cases = [sim.CASE_BY_NAME[n] for n in sim.SELECTED if sim.CASE_BY_NAME[n].kind == "null"]
        misses, inventing, gained = [], [], []
        for case in effect_cases + null_cases:
            report = json.loads((folder / "camsim0" / case.name / "out" / "report.json").read_text())
            named = sim.named_causes(report)
            if case.kind == "null":
                if report["extended"]["effects"]:
                    gained.append(f"{case.name} gained {sorted(report['extended']['effects'])}")
                continue
            if not case.planted <= named:
                misses.append(f"{case.name} named {sorted(named)}")
            unplanted = named - case.planted - sim.tolerated(case, sim.case_camera(case)[2])
            if len(unplanted) > 1:
                inventing.append(f"{case.name} unplanted {sorted(unplanted)}")
        named_cases = len(effect_cases) - len(misses)
        print(
            f"seed {seed}: {named_cases} of {len(effect_cases)} effect cases named; misses: {'; '.join(misses)}"
            + (f"; more than one unplanted cause: {'; '.join(inventing)}" if inventing else "")
            + (f"; null cases that gained an effect: {'; '.join(gained)}" if gained else "")
        )


if __name__ == "__main__":
    main()
