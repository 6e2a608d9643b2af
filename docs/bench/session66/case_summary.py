"""One line per camsim case calibrated by ``camsim_core_batch.sh`` or ``session64/run_camsim_case.py``: the named
causes, the base and written models' held-out RMSE, and the selection's steps (validation error after each).

usage: python docs/bench/session66/case_summary.py OUTDIR... > out.txt
"""

import json
import sys
from pathlib import Path


def main() -> None:
    for out in sys.argv[1:]:
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


if __name__ == "__main__":
    main()
