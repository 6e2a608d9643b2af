"""One calibration ``report.json`` per block, in a few lines: what the raw camsim outputs in this folder hold.

Usage: ``python docs/bench/camsim_report_summary.py REPORT.json...`` (the reports a camsim run keeps under pytest's
``--basetemp``, e.g. ``CAMSIM_SEED=... CAMSIM_CASES=... pytest --runxfail --basetemp=DIR
tests/calibration/test_independent_sim.py``). Prints the written model's effects, the findings and the noise
decision; each selection step with its validation error, the errors of what it tried and the groups it set aside; each identification with
its reasons and parameters; the base's parameters and both held-out RMSEs.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def summary(path: str) -> list[str]:
    report = json.loads(Path(path).read_text())
    lines = [
        f"== {path}",
        f"effects {report['extended']['effects']} findings {[f['effect'] for f in report.get('findings', [])]} "
        f"noise {report.get('noise', {}).get('kept')}",
    ]
    for step in report["selection"]["steps"]:
        tried = {k: round(v, 3) for k, v in step["tried"].items()}
        lines.append(f" step {step['effects']} {round(step['validation_error'], 3)} {tried}")
        # reports since session 19 (session 18's called it "pinned"; earlier ones had neither)
        for group, reason in step.get("set_aside", {}).items():
            lines.append(f"   set aside {group}: {reason}")
    for result in report["identification"]:
        params = {k: round(v, 3) for k, v in result["params"].items()}
        lines.append(f" id {result['effect']} {result['status']} {result['reasons']} {params}")
    base = {k: round(v, 4) for k, v in report["base"]["params"].items()}
    lines.append(
        f" base params {base} heldout base {round(report['base']['heldout_rmse'], 3)} "
        f"ext {round(report['extended']['heldout_rmse'], 3)}"
    )
    return lines


if __name__ == "__main__":
    for report_path in sys.argv[1:]:
        print("\n".join(summary(report_path)))
