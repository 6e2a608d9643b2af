"""One line per camsim case calibrated by ``camsim_core_batch.sh`` or ``session64/run_camsim_case.py``: the named
causes, the base and written models' held-out RMSE, and the selection's steps (validation error after each).

usage: python docs/bench/session66/case_summary.py [--with TERM] OUTDIR... > out.txt

``--with TERM``: also, per selection step, the best validation error of a group holding TERM among those the step
tried, and the reasons a group holding TERM was set aside.
"""

import json
import sys
from pathlib import Path


def main() -> None:
    args = sys.argv[1:]
    term = None
    if args[:1] == ["--with"]:
        term, args = args[1], args[2:]
    for out in args:
        for report_path in sorted(Path(out).glob("bt_*/camsim0/*/out/report.json")):
            report = json.loads(report_path.read_text())
            case, seed = report_path.parents[1].name, report_path.parents[3].name.removeprefix("bt_")
            named = sorted(x["effect"] for x in report["identification"] if x["identified"])
            steps = " -> ".join(
                f"{'+'.join(s['effects']) or 'base'} {s['validation_error']:.2f}"
                for s in report["selection"]["steps"]
            )
            print(
                f"{Path(out).name} {seed} {case}: named {named}; held-out base {report['base']['heldout_rmse']:.2f}, "
                f"written {report['extended']['heldout_rmse']:.2f}; steps {steps}"
            )
            if term is None:
                continue
            for step in report["selection"]["steps"]:
                tried = {k: v for k, v in step["tried"].items() if term in k.split("+")}
                best = min(tried.items(), key=lambda kv: kv[1]) if tried else None
                aside = {k: v for k, v in step.get("set_aside", {}).items() if term in k.split("+")}
                print(
                    f"    after {'+'.join(step['effects']) or 'base'} ({step['validation_error']:.2f}): best with "
                    f"{term} {f'{best[0]} {best[1]:.2f}' if best else 'none tried'}; set aside: {aside or 'none'}"
                )


if __name__ == "__main__":
    main()
