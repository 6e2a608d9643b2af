"""What the calibration names on the test simulator's drifting tables, by where a drifting recording starts.

``test_recordings_that_drift_are_named_and_locked_ones_are_not``'s draw (its camera, two of five recordings drifting
a third to two thirds of a period, bootstrap 10) for one ``STRIPES_SEED``, with recordings that start at any
whole-stripe placement or as their stripes come whole into view. Prints one line: named, withdrawn, held-out RMSE.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session33/drift_start_naming.py SEED placement|entry``
"""

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def main(seed: int, start_at: str) -> None:
    # the test module reads its seed at import
    os.environ["STRIPES_SEED"] = str(seed)
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    rng = np.random.default_rng([seed, 7])
    camera = test_stripes.draw_camera(rng, "interior")
    drifts = np.zeros(5)
    drifts[rng.choice(5, 2, replace=False)] = rng.uniform(0.33, 0.67, 2)
    scratch = Path(tempfile.mkdtemp())
    began = time.time()
    test_stripes.drifting_table(scratch / "d.csv", camera, rng, drifts, start_at=start_at)
    tabled = time.time()
    report = test_stripes.calibrate_stripes(scratch, scratch / "d.csv", camera["height"], bootstrap=10)
    named = sorted(f["effect"] for f in report["findings"])
    withdrawn = [w["effect"] for w in report["selection"].get("withdrawn", [])]
    print(
        seed,
        start_at,
        np.round(drifts, 2).tolist(),
        "named",
        named,
        "withdrawn",
        withdrawn,
        "held",
        round(report["extended"]["heldout_rmse"], 2),
        f"table {tabled - began:.0f}s cal {time.time() - tabled:.0f}s",
        flush=True,
    )


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2])
