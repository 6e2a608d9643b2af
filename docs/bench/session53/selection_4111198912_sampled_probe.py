"""Selection on drawn camera 4111198912 lit (sampled pulses), as
test_an_offset_taken_with_the_threshold_is_judged_with_the_noise_the_pair_made_possible runs it: held-out, the written
model, each selection step's cross-validated scores, identification.

Usage: ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session53/selection_4111198912_sampled_probe.py``
"""

import json
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("STRIPES_SEED", "4111198912")
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

with tempfile.TemporaryDirectory() as tmp:
    camera, report = ts.calibrate_drawn_camera(
        Path(tmp), 4111198912, "lit", "exposure_us", calibration_seed=912, bootstrap=10, pulses="sampled"
    )
e = report["extended"]
print("held-out", round(e["heldout_rmse"], 3), "base", round(report["base"]["heldout_rmse"], 3))
print("effects", sorted(e["effects"]), "params", e["params"])
print("withdrawn", report["selection"]["withdrawn"])
for step in report["selection"]["steps"]:
    print(
        "step",
        json.dumps(
            {k: step[k] for k in step if k in ("added", "tried", "tied", "score", "chosen")}, default=str
        )[:900],
    )
for r in report["identification"]:
    print("ident", r["effect"], r.get("identified"), r.get("compared_steps"), r.get("reasons"))
