"""What the calibration names on the test simulator's drifting tables: two recordings drifting (from any whole
placement, or from the entry) or every recording locked.

``test_recordings_that_drift_are_named_and_locked_ones_are_not``'s draw for one ``STRIPES_SEED``, each case drawn as
that test draws it (its camera; two of five recordings drifting a third to two thirds of a period, none for
``locked``; bootstrap 10). Prints one line: drifts, named, withdrawn, the drifts locked for want of evidence in the
written model, held-out RMSE. Session 33's ``drift_start_naming.py`` printed the same for the two drifting cases.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session34/drift_naming.py SEED placement|entry|locked``
"""

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CASES = ("placement", "entry", "locked")


def main(seed: int, case: str) -> None:
    if case not in CASES:
        raise SystemExit(f"case {case!r} unknown; valid: {', '.join(CASES)}")
    # the test module reads its seed at import
    os.environ["STRIPES_SEED"] = str(seed)
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    rng = np.random.default_rng([seed, 7])
    camera = test_stripes.draw_camera(rng, "interior")
    drifts = np.zeros(5)
    if case != "locked":
        drifts[rng.choice(5, 2, replace=False)] = rng.uniform(0.33, 0.67, 2)
    scratch = Path(tempfile.mkdtemp())
    began = time.time()
    start_at = "placement" if case == "locked" else case
    test_stripes.drifting_table(scratch / "d.csv", camera, rng, drifts, start_at=start_at)
    tabled = time.time()
    report = test_stripes.calibrate_stripes(scratch, scratch / "d.csv", camera["height"], bootstrap=10)
    named = sorted(f["effect"] for f in report["findings"])
    withdrawn = [w["effect"] for w in report["selection"].get("withdrawn", [])]
    print(
        seed,
        case,
        np.round(drifts, 2).tolist(),
        "named",
        named,
        "withdrawn",
        withdrawn,
        "locked for want of evidence",
        report["extended"]["derived"].get("drifts_locked_for_want_of_evidence"),
        "held",
        round(report["extended"]["heldout_rmse"], 2),
        f"table {tabled - began:.0f}s cal {time.time() - tabled:.0f}s",
        flush=True,
    )


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2])
