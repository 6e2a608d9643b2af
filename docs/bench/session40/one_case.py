"""One drawn second camera of ``test_stripes`` calibrated as ``test_second_camera_heldout_rows_and_parameters`` does
(``calibrate_drawn_camera``), printing the camera, selection's steps (scores of every group tried, ties) and the
written model. Run from a checkout, whose package is what is measured:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session40/one_case.py SEED lit|interior \
        exposure_us|exposure OUT_DIR
"""

import json
import os
import sys
from pathlib import Path

seed, frames, style, out = int(sys.argv[1]), sys.argv[2], sys.argv[3], Path(sys.argv[4])
os.environ["STRIPES_SEED"] = str(seed)  # the test module draws its seed at import
sys.path.insert(0, str(Path("tests/calibration").resolve()))
import test_stripes  # noqa: E402

out.mkdir(parents=True, exist_ok=True)
camera, report = test_stripes.calibrate_drawn_camera(out, seed, frames, style, seed % 1000)
print("camera", json.dumps({k: v for k, v in camera.items() if not hasattr(v, "__len__")}, default=str))
for index, step in enumerate(report["selection"]["steps"]):
    print(f"step {index} {step['effects']}: {step['validation_error']!r}")
    for group, score in step["tried"].items():
        print(
            f"    tried {group}: {score!r}"
            + (f" (set aside: {step['set_aside'][group]})" if group in step["set_aside"] else "")
        )
    if step.get("tied"):
        print(f"    taken over a tie with {step['tied']}")
extended = report["extended"]
print(
    "written", sorted(extended["effects"]), extended["params"], f"held-out {extended['heldout_rmse']!r} rows"
)
