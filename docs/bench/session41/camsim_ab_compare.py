"""Two camsim core batches (``docs/bench/camsim_core_batch.sh``) of the same master seeds compared case by case: each
case's written effects, held-out RMSE, identified effects, withdrawals and the steps each effect's ratio compares,
from the ``report.json`` under each batch's pytest basetemp. Prints one line per case that differs and a count.

    python docs/bench/session41/camsim_ab_compare.py BEFORE_DIR AFTER_DIR SEED [SEED ...]
"""

import json
import sys
from pathlib import Path


def cases(batch: Path, seed: str) -> dict[str, dict]:
    found = {}
    for report in sorted((batch / f"bt_{seed}").glob("*/*/out/report.json")):
        data = json.loads(report.read_text())
        found[report.parent.parent.name] = {
            "written": sorted(data["extended"]["effects"]),
            "heldout_rmse": round(data["extended"]["heldout_rmse"], 6),
            "identified": sorted(r["effect"] for r in data["identification"] if r["identified"]),
            "withdrawn": [w["effect"] for w in data["selection"]["withdrawn"]],
            # the selection steps each effect's ratio compares: where the group rule of session 41 applies, they move
            "compared_steps": {r["effect"]: r.get("compared_steps") for r in data["identification"]},
        }
    return found


before_dir, after_dir, seeds = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3:]
compared = differing = 0
for seed in seeds:
    before, after = cases(before_dir, seed), cases(after_dir, seed)
    if set(before) != set(after):
        print(f"seed {seed}: cases differ: {sorted(set(before) ^ set(after))}")
    for case in sorted(set(before) & set(after)):
        compared += 1
        if before[case] != after[case]:
            differing += 1
            print(f"seed {seed} {case}: {before[case]} -> {after[case]}")
print(f"{differing} of {compared} cases differ")
