"""One placement table of the drift test (tests/calibration/test_stripes.py, ``drift_reports``) traced: the first
selection step's scores, each selected effect's ratios, the written model's drifts, and per held-out row the written
model's prediction against the overlap with the drift (no entry start) and the locked model, all fitted on the fit rows.

usage: PYTHONPATH=TREE:tests/calibration:tests python docs/bench/session100/drift_trace.py OUT SEED
"""

import os
import sys
from pathlib import Path

os.environ["STRIPES_SEED"] = sys.argv[2]  # test_stripes reads it at import (its failure text names it)
os.environ.setdefault("HF_HUB_OFFLINE", "1")

import numpy as np
import test_stripes as ts
from drift_groups import calibrate_drift_table

import lerobot_phantom
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem


def interval(value: dict | None) -> str:
    return "-" if not value else f"{value['estimate']:.3f} [{value['low']:.3f}, {value['high']:.3f}]"


def main(out: Path, seed: int) -> None:
    print("# package:", Path(lerobot_phantom.__file__).resolve().parent)
    report, camera, drifts, table = calibrate_drift_table(out, seed, "placement")
    print(ts.camera_summary(camera), "drifts", np.round(drifts, 3).tolist())
    for k, step in enumerate(report["selection"]["steps"]):
        print(f"step {k}: {step['effects']} {step['validation_error']:.2f}")
        for group, score in step["tried"].items():
            print(f"    tried {group}: {score:.2f}")
    for result in report["identification"]:
        print(
            f"{result['effect']}: identified {result['identified']}, compared steps {result['compared_steps']}, "
            f"ratio {interval(result['validation_ratio'])}, without it {interval(result['ratio_without'])}"
        )
    for withdrawal in report["selection"]["withdrawn"]:
        print(
            f"withdrawn after pass {withdrawal['pass']}: {withdrawal['effect']}: {' | '.join(withdrawal['reasons'])}"
        )
    for name, value in report["extended"]["params"].items():
        print(f"written {name} = {value:.4g}")
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    fit_items, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
    written = frozenset(report["extended"]["effects"])
    models = {
        "written": problem.fit(written, fit_items),
        "overlap+drift": problem.fit(frozenset({"exposure_overlap", "phase_drift"}), fit_items),
        "locked": problem.fit(frozenset({"exposure_overlap"}), fit_items),
    }
    for name, fit in models.items():
        drift_values = [round(fit.params.get(n, 0.0), 3) for n in problem.drift_names]
        print(
            f"{name} ({sorted(fit.effects)}): held-out {problem.rmse(fit, heldout):.2f} rows, drifts {drift_values}"
        )
    predicted = {name: problem.predict_fit(fit, heldout) for name, fit in models.items()}
    for i, item in enumerate(heldout):
        row = " ".join(f"{name} {values[i]:7.2f}" for name, values in predicted.items())
        print(f"{problem.item_label(item):42s} measured {problem.rows[item]:7.2f} | {row}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), int(sys.argv[2]))
