"""A stripe table's drift forms side by side on ten held-out splits: the locked model, ``phase_drift`` (a recording
starts at any whole-stripe placement) and ``phase_drift`` + ``drift_from_entry`` (it starts as its stripes come
whole into view).

Usage: ``python docs/bench/session33/drift_forms.py TABLE OUT_TXT --image-height 720 --exposure-unit-s 1e-6``.
Per split seed (the CLI's split and inner folds): each model's 4-fold cross-validated mean per-item error on the fit
rows (selection's score), its held-out RMSE when fitted on all fit rows, and the recordings' fitted drifts above
0.005. Prints no table values. Refuses to overwrite OUT_TXT. Made for the Axis table of "They See Me Rollin'"
(GPL-3.0, not in this repository: read it by path).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from lerobot_phantom.calibration.core import cross_validated, kfold, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

OVERLAP = frozenset({"exposure_overlap", "integration_offset"})
MODELS = {
    "locked": OVERLAP,
    "placement": OVERLAP | {"phase_drift"},
    "entry": OVERLAP | {"phase_drift", "drift_from_entry"},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--image-height", type=int, required=True)
    parser.add_argument("--exposure-unit-s", type=float, required=True)
    parser.add_argument("--seeds", type=int, default=10)
    args = parser.parse_args()
    if args.out.exists():
        raise SystemExit(f"{args.out} exists: pass a new path (this script never overwrites a result)")
    problem = StripeProblem(args.table, image_height=args.image_height, exposure_unit_s=args.exposure_unit_s)
    lines = [
        f"{args.table.name}: fit on the CLI's split (held-out 0.2), 4 inner folds (seed + 1), as selection does"
    ]
    for seed in range(args.seeds):
        began = time.process_time()
        fit_items, heldout = seeded_split(problem.n_items, 0.2, seed)
        splits = kfold(fit_items, 4, seed + 1, 2500)
        cells = []
        for name, effects in MODELS.items():
            score, _, _ = cross_validated(problem, effects, splits, None)
            fit = problem.fit(effects, fit_items)
            drifts = {
                k.removeprefix("drift_"): round(v, 3)
                for k, v in fit.params.items()
                if k.startswith("drift_") and v > 0.005
            }
            cells.append(f"{name}: cv {score:.3f} held-out {problem.rmse(fit, heldout):.2f} drifts {drifts}")
        lines.append(f"seed {seed} ({time.process_time() - began:.0f} s CPU)\n  " + "\n  ".join(cells))
        print(lines[-1], flush=True)
    args.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
