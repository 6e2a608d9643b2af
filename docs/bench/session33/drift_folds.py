"""One held-out split of a stripe table, fold by fold: the recordings' drifts each inner fold fits with the entry start,
and the validation rows whose error that model changes most against the locked one (selection's folds and per-item
score). Prints fitted drifts and per-row errors, each row labelled as the report labels it (its settings and its
frames' spread against the table's median).

Usage: ``python docs/bench/session33/drift_folds.py TABLE SEED --image-height 720 --exposure-unit-s 1e-6``.
"""

import argparse
from pathlib import Path

from lerobot_phantom.calibration.core import cross_validated, kfold, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("table", type=Path)
parser.add_argument("seed", type=int)
parser.add_argument("--image-height", type=int, required=True)
parser.add_argument("--exposure-unit-s", type=float, required=True)
args = parser.parse_args()
problem = StripeProblem(args.table, image_height=args.image_height, exposure_unit_s=args.exposure_unit_s)
fit_items, _ = seeded_split(problem.n_items, 0.2, args.seed)
splits = kfold(fit_items, 4, args.seed + 1, 2500)
locked = frozenset({"exposure_overlap", "integration_offset"})
entry = locked | {"phase_drift", "drift_from_entry"}
locked_score, _, locked_items = cross_validated(problem, locked, splits, None)
entry_score, entry_fits, entry_items = cross_validated(problem, entry, splits, None)
print(
    f"split seed {args.seed}: cross-validated mean per-row error locked {locked_score:.3f}, entry {entry_score:.3f}"
)
for k, fit in enumerate(entry_fits):
    drifts = {
        n.removeprefix("drift_"): round(v, 3)
        for n, v in fit.params.items()
        if n.startswith("drift_") and v > 0.005
    }
    print(f"fold {k}: drifts {drifts}")
changes = sorted((entry_items[i] - locked_items[i], i) for i in locked_items)
for _change, item in changes[-4:][::-1] + changes[:3]:
    print(f"{problem.item_label(item)}: locked {locked_items[item]:.1f}, entry {entry_items[item]:.1f} rows")
