"""camsim's unexplained projection falloff (``projection_falloff_unnamed``) on one master seed: the camera, the base and
written models' held-out RMSE, and each selected effect's identification (validation ratio with its 90% interval,
parameters and their intervals, reasons).

Usage: ``PYTHONPATH=. python docs/bench/session45/falloff_detail.py MASTER_SEED`` from a checkout's root.
"""

import importlib
import os
import sys
import tempfile

sys.path.insert(0, "tests/calibration")
os.environ["CAMSIM_SEED"] = sys.argv[1]
sim = importlib.import_module("test_independent_sim")
with tempfile.TemporaryDirectory() as root:
    result = sim.run_case("projection_falloff_unnamed", root)
r = result["report"]
print("camera", result["camera"])
print(
    "base",
    round(r["base"]["heldout_rmse"], 3),
    "written",
    r["extended"]["effects"],
    round(r["extended"]["heldout_rmse"], 3),
)
for x in r["identification"]:
    v = x["validation_ratio"]
    print(
        x["effect"],
        x["status"],
        "ratio",
        round(v["estimate"], 3),
        "interval",
        round(v["low"], 3),
        round(v["high"], 3),
        "params",
        x["params"],
        {k: (round(i["low"], 4), round(i["high"], 4)) for k, i in x["intervals"].items()},
        x["reasons"],
    )
for s in r["selection"]["steps"]:
    print("step", s.get("added"), s.get("validation_error"))
