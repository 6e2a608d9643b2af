"""camsim's unexplained projection falloff (``projection_falloff_unnamed``) on one master seed: the camera, the base and
written models' held-out RMSE, and each selected effect's identification (validation ratio with its 90% interval,
parameters and their intervals, reasons).

Usage: ``PYTHONPATH=. python docs/bench/session45/falloff_detail.py MASTER_SEED`` from a checkout's root.
"""

import sys

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

sim, result = run_on_master_seed("projection_falloff_unnamed", sys.argv[1])
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
