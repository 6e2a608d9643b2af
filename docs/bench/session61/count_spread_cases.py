"""camsim EM truncation cases calibrated by whichever package is on ``PYTHONPATH`` (session 61), one line per
master seed.

``PYTHONPATH=<checkout> python docs/bench/session61/count_spread_cases.py OUTDIR CASE MASTER_SEED...`` renders
``CASE`` as this checkout's ``tests/calibration/test_independent_sim.py`` does under each ``CAMSIM_SEED`` (the
simulator is always this checkout's, so an older package meets the same frames) and prints what is named, whether
the case passes its test's rule, the fitted count law (slope, and the jitter in rows of the frame) and the
held-out figures: the predictive RMSE the report scores, its interval, and the error of the best registration.
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

TESTS = Path(__file__).resolve().parents[3] / "tests"
sys.path.insert(0, str(TESTS / "calibration"))
sys.path.insert(1, str(TESTS))


def main() -> None:
    import lerobot_phantom

    out, name, seeds = Path(sys.argv[1]), sys.argv[2], sys.argv[3:]
    print(f"# package {Path(lerobot_phantom.__file__).parent}, simulator {TESTS}", flush=True)
    for master in seeds:
        os.environ["CAMSIM_SEED"] = master
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        case = sim.CASE_BY_NAME[name]
        result = sim.run_case(name, str(out / master))
        report, height = result["report"], result["camera"].height
        params = report["extended"]["params"]
        heldout = report["extended"]
        low, high = heldout["heldout_rmse_interval"]["low"], heldout["heldout_rmse_interval"]["high"]
        print(
            f"{name} {master} (case seed {result['seed']}) "
            f"{'pass' if sim.passes(case, report, result['camera']) else 'FAIL'} "
            f"named {sorted(sim.named_causes(report))} slope {params['ratio_per_intensity']:.4f} "
            f"jitter {params['ratio_jitter'] * height:.2f} rows | heldout {heldout['heldout_rmse']:.3f} "
            f"[{low:.3f}, {high:.3f}] registered {heldout.get('heldout_registered_rmse', float('nan')):.3f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
