"""Two camsim batches (``docs/bench/camsim_core_batch.sh``) of the same master seeds: what each case's report says
is left in the residual (``unexplained_structure``), case by case, and whether the written model is the same.

    python docs/bench/session45/structure_ab_compare.py BEFORE_DIR AFTER_DIR SEED [SEED ...]

One line per case: the case's kind (from its name: ``*_null``, ``*_unnamed`` or an effect case), the variables
flagged before and after, and ``same model`` when the written effects and held-out RMSE agree. Then counts per kind.
"""

import json
import sys
from collections import Counter
from pathlib import Path


def kind(case: str) -> str:
    return "null" if case.endswith("_null") else "unexplained" if case.endswith("_unnamed") else "effect"


def flagged(report: dict) -> tuple[str, ...]:
    structure = report["unexplained_structure"]
    return tuple(t["variable"] for t in structure["tests"] if t["significant"])


def cases(batch: Path, seed: str) -> dict[str, dict]:
    found = {}
    for path in sorted((batch / f"bt_{seed}").glob("*/*/out/report.json")):
        report = json.loads(path.read_text())
        found[path.parent.parent.name] = {
            "model": (
                tuple(sorted(report["extended"]["effects"])),
                round(report["extended"]["heldout_rmse"], 9),
            ),
            "flagged": flagged(report),
            "tested_on": report["unexplained_structure"]["tested_on"],
        }
    return found


before_dir, after_dir, seeds = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3:]
counts = Counter()
for seed in seeds:
    before, after = cases(before_dir, seed), cases(after_dir, seed)
    for case in sorted(set(before) & set(after)):
        b, a = before[case], after[case]
        same = "same model" if b["model"] == a["model"] else f"MODEL {b['model']} -> {a['model']}"
        print(
            f"{seed} {case:32s} {kind(case):11s} {same} | before {list(b['flagged']) or 'none'} | "
            f"after {list(a['flagged']) or 'none'}"
        )
        counts[(kind(case), "before", bool(b["flagged"]))] += 1
        counts[(kind(case), "after", bool(a["flagged"]))] += 1
for k in ("null", "effect", "unexplained"):
    for side in ("before", "after"):
        n = counts[(k, side, True)] + counts[(k, side, False)]
        print(f"{k:11s} {side:6s}: structure reported in {counts[(k, side, True)]} of {n} cases")
