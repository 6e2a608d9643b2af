"""The entry-form drift of one stripe-table split over item-bootstrap refits, as identification draws them: per
draw the exposure-50 drift, the drifts locked for want of evidence, and which of that sweep's 5-30% duty videos the
draw holds (split composition and fitted values only, no measured value).

Usage: ``python docs/bench/session34/bootstrap_drift_draws.py TABLE SEED DRAWS --image-height 720
--exposure-unit-s 1e-6`` (a generator seeded 0; identification's own draws use the CLI's generator)
"""

import argparse
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.identify import resample
from lerobot_phantom.calibration.stripes import StripeProblem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("table", type=Path)
parser.add_argument("seed", type=int)
parser.add_argument("draws", type=int)
parser.add_argument("--image-height", type=int, required=True)
parser.add_argument("--exposure-unit-s", type=float, required=True)
parser.add_argument("--recording", default="drift_25Hz_exposure50")
args = parser.parse_args()
problem = StripeProblem(args.table, image_height=args.image_height, exposure_unit_s=args.exposure_unit_s)
items, _ = seeded_split(problem.n_items, 0.2, args.seed)
effects = frozenset({"exposure_overlap", "integration_offset", "phase_drift", "drift_from_entry"})
estimate = problem.fit(effects, items)
print(f"estimate: {args.recording} {estimate.params[args.recording]:.3f}")
rng = np.random.default_rng(0)
recording = problem.drift_names.index(args.recording)
locked = 0
for draw in range(args.draws):
    sample = resample(items, rng)
    fit = problem.fit(effects, sample, start=estimate)
    duties = sorted(
        {
            round(100 * problem.duty[i])
            for i in sample
            if problem.recording[i] == recording and problem.duty[i] >= 0.05
        }
    )
    locked += fit.params[args.recording] == 0.0
    print(
        f"draw {draw}: {args.recording} {fit.params[args.recording]:.3f}, holds its videos at {duties}% duty; "
        f"locked for want of evidence: {', '.join(fit.extra['drifts_locked_for_want_of_evidence'])}"
    )
print(f"{args.recording} locked on {locked} of {args.draws} draws")
