"""The entry-drift test's held-out comparison on its own 8 held-out rows and on fresh tables of the same draw.

For each STRIPES_SEED given: the test's camera, drifts and table (tests/calibration/test_stripes.py's
drifting_draw + drifting_table, start "entry"), the extended model the calibration selects (refitted here on the
fit rows; its held-out error is checked against report.json's), and the test's locked model (the extended effects
without the drifts, fitted on the same rows). Both fits then predict (a) the 8 held-out rows, row by row, and
(b) every row of REPLICATES fresh tables drawn from the same camera and drifts (the generator continued after the
first table). Prints per-row residuals and the RMSEs.

    STRIPES_SEED=0 python docs/bench/session38/drift_heldout_replicates.py 1002 3142600619 1001
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
os.environ.setdefault("STRIPES_SEED", "0")
os.environ.setdefault("HF_HUB_OFFLINE", "1")

import test_stripes as ts

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.stripes import DRIFT_EFFECTS, StripeProblem

REPLICATES = 3


def main(seeds: list[int]) -> None:
    for seed in seeds:
        ts.SEED = seed
        rng, camera, drifts = ts.drifting_draw(seed, drifting=True)
        out = Path(tempfile.mkdtemp())
        table = out / "drifting.csv"
        ts.drifting_table(table, camera, rng, drifts, start_at="entry")
        report = ts.calibrate_stripes(out, table, camera["height"], bootstrap=10)
        problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
        fit_items, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
        effects = frozenset(report["extended"]["effects"])
        extended = problem.fit(effects, fit_items)
        locked = problem.fit(effects - set(DRIFT_EFFECTS), fit_items)
        print(f"STRIPES_SEED={seed} drifts {np.round(drifts, 3)} effects {sorted(effects)}")
        print(
            f"  report held-out {report['extended']['heldout_rmse']:.2f}, refit {problem.rmse(extended, heldout):.2f}"
        )
        print(
            f"  locked frames {locked.extra.get('frames')}, extended drifts "
            + ", ".join(f"{k}={v:.3f}" for k, v in extended.params.items() if k.startswith("drift_"))
        )
        print("  held-out row: exposure_us duty measured extended_residual locked_residual")
        ext_res, lock_res = problem.residual(extended, heldout), problem.residual(locked, heldout)
        for item, e, lo in zip(heldout, ext_res, lock_res, strict=True):
            print(
                f"    {problem.exposure_setting[item]:g} {problem.duty[item]:.2f} {problem.rows[item]:.2f} {e:+.2f} {lo:+.2f}"
            )
        print(
            f"  held-out rmse: extended {np.sqrt(np.mean(ext_res**2)):.2f} locked {np.sqrt(np.mean(lock_res**2)):.2f}"
        )
        every = np.arange(problem.n_items)
        for k in range(REPLICATES):
            fresh = out / f"replicate{k}.csv"
            ts.drifting_table(fresh, camera, rng, drifts, start_at="entry")
            other = StripeProblem(fresh, image_height=camera["height"], exposure_unit_s=None)
            print(
                f"  replicate {k}: all {other.n_items} rows rmse extended {other.rmse(extended, every):.2f} "
                f"locked {other.rmse(locked, every):.2f}; its held-out rows extended "
                f"{other.rmse(extended, heldout):.2f} locked {other.rmse(locked, heldout):.2f}"
            )
        sys.stdout.flush()


if __name__ == "__main__":
    main([int(s) for s in sys.argv[1:]])
