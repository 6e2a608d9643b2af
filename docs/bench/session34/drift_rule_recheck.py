"""Whether the drift rule's single refit leaves a kept drift below the bar: the written model's effects fitted on a
split's fit rows (the rule applied, as in every fit), then the rule asked again of the refitted parameters. Prints
per split the drifts locked by the fit and those the rule would lock on a second pass (none: the refit kept every
drift's evidence).

Usage: ``python docs/bench/session34/drift_rule_recheck.py TABLE --seeds 0-9 --image-height H --exposure-unit-s U``
"""

import argparse
from pathlib import Path

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("table", type=Path)
parser.add_argument("--seeds", default="0-9")
parser.add_argument("--image-height", type=int, required=True)
parser.add_argument("--exposure-unit-s", type=float, required=True)
args = parser.parse_args()
first, last = (int(s) for s in args.seeds.split("-"))
problem = StripeProblem(args.table, image_height=args.image_height, exposure_unit_s=args.exposure_unit_s)
effects = frozenset({"exposure_overlap", "integration_offset", "phase_drift", "drift_from_entry"})
for seed in range(first, last + 1):
    fit_items, _ = seeded_split(problem.n_items, 0.2, seed)
    fit = problem.fit(effects, fit_items)
    again = problem.drifts_without_evidence(effects, fit.params, fit_items)
    kept = {n: round(fit.params[n], 4) for n in problem.drift_names if fit.params[n] > 0}
    print(
        f"split {seed}: locked by the fit {len(fit.extra['drifts_locked_for_want_of_evidence'])}, "
        f"kept {kept}, a second pass would lock {again or 'none'}"
    )
