"""blur_rotation_unnamed on one master seed: the report's unexplained-structure section and selection.

Usage: ``PYTHONPATH=. python docs/bench/session45/rotation_case_report.py MASTER_SEED`` from a checkout's root (its
package is the one tested). Session 45 ran it at d0f238e and 8354629 on CAMSIM_SEED=3875164730.
"""

import json
import sys

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

sim, result = run_on_master_seed("blur_rotation_unnamed", sys.argv[1])
report = result["report"]
print("seed", result["seed"], "named", sorted(sim.named_causes(report)))
print(
    "base",
    report["base"]["heldout_rmse"],
    "extended",
    report["extended"]["heldout_rmse"],
    report["extended"]["effects"],
)
print("withdrawn", report.get("selection", {}).get("withdrawn"))
print(json.dumps(report.get("unexplained_structure"), indent=1, default=str))
