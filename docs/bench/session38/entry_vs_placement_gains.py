"""The entry-vs-placement test's figures for one STRIPES_SEED: on the placement and the entry table of the drift
tests' draw (tests/calibration/test_stripes.py), the named effects, the cross-validated gain interval of
drift_from_entry and phase_drift, and each recording's fitted drift.

    python docs/bench/session38/entry_vs_placement_gains.py SEED
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


def main(seed: int) -> None:
    ts.SEED = seed
    for start_at in ("placement", "entry"):
        rng, camera, drifts = ts.drifting_draw(seed, drifting=True)
        out = Path(tempfile.mkdtemp())
        table = out / "drifting.csv"
        ts.drifting_table(table, camera, rng, drifts, start_at=start_at)
        report = ts.calibrate_stripes(out, table, camera["height"], bootstrap=10)
        named = sorted(f["effect"] for f in report["findings"])
        params = report["extended"].get("params", {})
        print(f"STRIPES_SEED={seed} {start_at}: truth drifts {np.round(drifts, 3)}; named {named}")
        for effect in ("phase_drift", "drift_from_entry"):
            for result in report["identification"]:
                if result["effect"] == effect:
                    ratio = result["validation_ratio"]
                    print(
                        f"  {effect}: identified {result['identified']}, gain {ratio.get('estimate', float('nan')):.3g} "
                        f"[{ratio['low']:.3g}, {ratio['high']:.3g}]"
                    )
        print("  drifts " + ", ".join(f"{k}={v:.3f}" for k, v in params.items() if k.startswith("drift_")))
        print(
            f"  locked for want of evidence {report['extended']['derived'].get('drifts_locked_for_want_of_evidence')}"
        )
        print(f"  held-out {report['extended']['heldout_rmse']:.2f} rows", flush=True)


if __name__ == "__main__":
    for seed in sys.argv[1:]:
        main(int(seed))
