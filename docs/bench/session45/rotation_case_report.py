"""blur_rotation_unnamed on one master seed: the report's unexplained-structure section and selection.

Usage: ``PYTHONPATH=. python docs/bench/session45/rotation_case_report.py MASTER_SEED`` from a checkout's root (its
package is the one tested). Session 45 ran it at d0f238e and 8354629 on CAMSIM_SEED=3875164730.
"""

import importlib
import json
import os
import sys
import tempfile

sys.path.insert(0, "tests/calibration")
os.environ["CAMSIM_SEED"] = sys.argv[1]
sim = importlib.import_module("test_independent_sim")
with tempfile.TemporaryDirectory() as root:
    result = sim.run_case("blur_rotation_unnamed", root)
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
