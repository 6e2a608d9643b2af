"""Two camsim batch runs of the same master seeds (``camsim_core_batch.sh`` OUTDIRs), case by case: the written
model, the held-out RMSE and the residual-structure verdict of each, and the pattern-detail test where the later run
has it. Usage: ``python docs/bench/session31/structure_flags_compare.py BEFORE_DIR AFTER_DIR``."""

from __future__ import annotations

import json
import sys
from pathlib import Path


def reports(root: Path) -> dict[tuple[str, str], dict]:
    found = {}
    for path in sorted(root.glob("bt_*/camsim0/*/out/report.json")):
        seed, case = path.parts[-5].removeprefix("bt_"), path.parts[-3]
        found[seed, case] = json.loads(path.read_text())
    return found


def verdict(report: dict) -> str:
    structure = report["unexplained_structure"]
    flagged = [t["variable"] for t in structure["tests"] if t.get("significant")]
    return ("structure: " + ",".join(flagged)) if structure["structure_remains"] else "no structure"


def main(before_dir: str, after_dir: str) -> None:
    before, after = reports(Path(before_dir)), reports(Path(after_dir))
    same_models = 0
    for key in sorted(set(before) & set(after)):
        a, b = before[key], after[key]
        same = a["extended"]["effects"] == b["extended"]["effects"] and (
            a["extended"]["heldout_rmse"] == b["extended"]["heldout_rmse"]
        )
        same_models += same
        detail = next(
            (t for t in b["unexplained_structure"]["tests"] if t["variable"] == "pattern_detail"), None
        )
        shown = (
            f" pattern_detail eta2 {detail['value']:.3f} (low {detail['interval']['low']:.3f})"
            if detail
            else ""
        )
        print(
            f"{key[0]} {key[1]:28s} {'same model' if same else 'MODEL DIFFERS'} | before {verdict(a)} | "
            f"after {verdict(b)}{shown}"
        )
    print(f"{same_models} of {len(set(before) & set(after))} cases write the same model and held-out RMSE")


if __name__ == "__main__":
    main(*sys.argv[1:])
