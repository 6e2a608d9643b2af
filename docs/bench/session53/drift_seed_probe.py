"""The drift-naming test's draw for a seed (test_recordings_that_drift_are_named_and_locked_ones_are_not, placement
starts): the camera, each recording's drift, and what calibration wrote and withdrew, with each step's scores and
each effect's identification (the reasons an effect was not identified).

Usage: ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session53/drift_seed_probe.py SEED``
"""

import json
import os
import sys
import tempfile
from pathlib import Path

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

seed = int(sys.argv[1])
rng, camera, drifts = ts.drifting_draw(seed, drifting=True)
print(ts.camera_summary(camera), "drifts", drifts)
with tempfile.TemporaryDirectory() as out:
    table = Path(out) / "drifting.csv"
    ts.drifting_table(table, camera, rng, drifts)
    print(table.read_text())
    report = ts.calibrate_stripes(Path(out), table, camera["height"], bootstrap=10)
extended = report["extended"]
print("held-out", round(extended["heldout_rmse"], 3), "base", round(report["base"]["heldout_rmse"], 3))
print("written", sorted(extended["effects"]), "params", extended["params"])
print("withdrawn", json.dumps(report["selection"]["withdrawn"], default=str))
for earlier in report["selection"].get("earlier_passes", []):
    print("earlier pass", json.dumps(earlier, default=str))
for step in report["selection"]["steps"]:
    print(
        "step",
        json.dumps({k: step[k] for k in ("effects", "validation_error", "tried", "set_aside")}, default=str),
    )
for result in report["identification"]:
    print("identification", result["effect"], result.get("identified"), result.get("reasons"))
