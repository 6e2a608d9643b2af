"""Every recording's entry-form drift over item-bootstrap refits of one stripe-table split, and the joint statistic
identification now judges ``phase_drift`` by (``identify.joint_null_interval``: the largest drift as a share of its
range, 0 only in a draw with every recording locked). Fitted values and split composition only, no measured value.

Usage: ``python docs/bench/session42/joint_drift_draws.py TABLE SEED DRAWS --image-height 720
--exposure-unit-s 1e-6`` (a generator seeded 0; identification's own draws use the CLI's generator)
"""

import argparse
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.identify import joint_null_interval, resample
from lerobot_phantom.calibration.stripes import StripeProblem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("table", type=Path)
parser.add_argument("seed", type=int)
parser.add_argument("draws", type=int)
parser.add_argument("--image-height", type=int, required=True)
parser.add_argument("--exposure-unit-s", type=float, required=True)
args = parser.parse_args()
problem = StripeProblem(args.table, image_height=args.image_height, exposure_unit_s=args.exposure_unit_s)
items, _ = seeded_split(problem.n_items, 0.2, args.seed)
effects = frozenset({"exposure_overlap", "integration_offset", "phase_drift", "drift_from_entry"})
estimate = problem.fit(effects, items)
nulls = problem.null_values("phase_drift")
bounds = {p.name: (p.low, p.high) for p in problem.param_specs(effects) if p.name in nulls}
short = {n: n.removeprefix("drift_25Hz_") for n in problem.drift_names}
print("estimate: " + ", ".join(f"{short[n]} {estimate.params[n]:.3f}" for n in problem.drift_names))
rng = np.random.default_rng(0)
samples = []
for draw in range(args.draws):
    fit = problem.fit(effects, resample(items, rng), start=estimate)
    samples.append(fit.params)
    drifting = {n: fit.params[n] for n in problem.drift_names if fit.params[n] > 0.0}
    print(
        f"draw {draw}: "
        + (", ".join(f"{short[n]} {v:.3f}" for n, v in drifting.items()) or "every drift locked")
    )
joint = joint_null_interval(nulls, bounds, estimate.params, samples)
at_null = sum(all(s[n] == 0.0 for n in problem.drift_names) for s in samples)
print(f"draws with every drift at its null: {at_null} of {args.draws}")
for name in problem.drift_names:
    locked = sum(s[name] == 0.0 for s in samples)
    print(f"{short[name]}: locked in {locked} of {args.draws} draws")
print(f"joint statistic: {joint.estimate:.4g} [{joint.low:.4g}, {joint.high:.4g}] over {joint.draws} draws")
