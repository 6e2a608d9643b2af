"""Each selection step of camsim reports: the model, its cross-validated score, the lowest-scoring groups it tried
(with the share of the score each is under the step's model) and the groups it set aside with the reason.

Usage: ``python docs/bench/session78/step_scores.py OUT CASE SEED...`` (OUT in ``session64/run_camsim_case.py``'s
layout: ``OUT/bt_SEED/camsim0/CASE/out/report.json``)."""

from __future__ import annotations

import json
import sys
from pathlib import Path


def main() -> None:
    out, case, seeds = Path(sys.argv[1]), sys.argv[2], sys.argv[3:]
    for seed in seeds:
        report = json.loads((out / f"bt_{seed}" / "camsim0" / case / "out" / "report.json").read_text())
        selection = report["selection"]
        print(f"{seed} {case}: selected {selection['selected']}, withdrawn {selection.get('withdrawn', [])}")
        for k, step in enumerate(selection["steps"]):
            score = step["validation_error"]
            lowest = sorted(step["tried"].items(), key=lambda kv: kv[1])[:8]
            tried = ", ".join(f"{g} {v:.3f} ({100 * (1 - v / score):+.1f}%)" for g, v in lowest)
            print(f"  step {k} {'+'.join(step['effects']) or 'base'} {score:.3f}; tried: {tried or 'none'}")
            for group, why in step.get("set_aside", {}).items():
                print(f"    set aside {group}: {why}")
        print(f"  named: {sorted(r['effect'] for r in report['identification'] if r['identified'])}")


if __name__ == "__main__":
    main()
