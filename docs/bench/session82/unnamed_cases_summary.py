"""Per drawn case in a ``run_camsim_case.py`` output folder: the named causes and whether structure was reported
(the verdict of an unexplained case: invent none, report structure).

Usage: PYTHONPATH=. python docs/bench/session82/unnamed_cases_summary.py OUTDIR"""

import json
import os
import sys
from pathlib import Path

sys.path[:0] = ["tests/calibration", "tests"]
os.environ.setdefault("CAMSIM_SEED", "0")  # read at import; the reports carry their own draws

from test_independent_sim import named_causes, unexplained_structure  # noqa: E402


def main(root: Path) -> None:
    for report_path in sorted(root.glob("bt_*/camsim0/*/out/report.json")):
        report = json.loads(report_path.read_text())
        case, master = report_path.parts[-3], report_path.parts[-5].removeprefix("bt_")
        structure = unexplained_structure(report)
        print(
            f"{master} {case}: named {sorted(named_causes(report)) or 'nothing'}; held-out base "
            f"{report['base']['heldout_rmse']:.2f}, written {report['extended']['heldout_rmse']:.2f}; structure "
            f"{'reported: ' + structure[:160] if structure else 'none reported'}"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]))
