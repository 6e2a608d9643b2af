"""The drift tests' table for one STRIPES_SEED and start, calibrated as the tests do (bootstrap 10): the table, the
last selection pass's steps, the withdrawals of every pass, and each effect's identification.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session39/selection_trace.py SEED placement|entry``
"""

import json
import os
import sys
import tempfile
from pathlib import Path


def main(seed: int, start_at: str) -> None:
    os.environ["STRIPES_SEED"] = str(seed)  # read by the test module at import
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    rng, camera, drifts = test_stripes.drifting_draw(seed, drifting=True)
    out = Path(tempfile.mkdtemp())
    table = out / "drifting.csv"
    test_stripes.drifting_table(table, camera, rng, drifts, start_at=start_at)
    report = test_stripes.calibrate_stripes(out, table, camera["height"], bootstrap=10)
    print(test_stripes.camera_summary(camera), f"drifts {drifts.round(3).tolist()} from {start_at}")
    print(table.read_text())
    print(json.dumps(report["selection"], indent=1, default=str))
    for result in report["identification"]:
        print(result["effect"], result["identified"], result.get("reasons"), result.get("validation_ratio"))
    print(f"held-out {report['extended']['heldout_rmse']:.2f} rows")


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2])
