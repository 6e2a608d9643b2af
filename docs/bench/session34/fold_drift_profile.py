"""One recording's drift in one selection fold of a stripe-table split, profiled: the fold's entry-form fit (before the
drift rule: the rule would lock what is profiled here), then the recording's drift moved over a grid with every
other parameter held. Per drift: which of the recording's fit videos the drift moves (by duty), the drop in the
recording's variance-weighted squared error against a lock (the statistic the drift rule compares with 2.706), and
how many rows the drift takes off each video the fold validates (model against model: no measured value is printed).

Usage: ``python docs/bench/session34/fold_drift_profile.py TABLE SEED FOLD RECORDING --image-height 720
--exposure-unit-s 1e-6`` (RECORDING: a drift name such as drift_25Hz_exposure75)
"""

import argparse
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.core import kfold, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("table", type=Path)
parser.add_argument("seed", type=int)
parser.add_argument("fold", type=int)
parser.add_argument("recording")
parser.add_argument("--image-height", type=int, required=True)
parser.add_argument("--exposure-unit-s", type=float, required=True)
args = parser.parse_args()
problem = StripeProblem(args.table, image_height=args.image_height, exposure_unit_s=args.exposure_unit_s)
fit_items, _ = seeded_split(problem.n_items, 0.2, args.seed)
train, validation = kfold(fit_items, 4, args.seed + 1, 2500)[args.fold]  # selection's folds (drift_folds.py)
effects = frozenset({"exposure_overlap", "integration_offset", "phase_drift", "drift_from_entry"})
problem.drifts_without_evidence = lambda *_: []  # the fit as it was before the rule
fit = problem.fit(effects, train)
index = problem.drift_names.index(args.recording)
mine, checked = train[problem.recording[train] == index], validation[problem.recording[validation] == index]
print(f"split {args.seed} fold {args.fold}: {args.recording} fitted at {fit.params[args.recording]:.3f}")
print(f"fit videos at {sorted(round(100 * float(problem.duty[i]), 1) for i in mine)}% duty")
values = {k: torch.tensor(v, dtype=torch.float64) for k, v in fit.params.items()}


def predict(drift: float, items: np.ndarray) -> np.ndarray:
    with torch.no_grad():
        drifted = values | {args.recording: torch.tensor(drift, dtype=torch.float64)}
        return problem.predict(effects, drifted, items, "interior").numpy()


residual = predict(fit.params[args.recording], train) - problem.rows[train]
measured_variance = problem.standard_error[train] ** 2
weight = 1.0 / (max(float(np.mean(residual**2 - measured_variance)), 1e-9) + measured_variance)
in_mine = problem.recording[train] == index
locked, locked_checked = predict(0.0, mine), predict(0.0, checked)
for drift in np.round(np.arange(0.0, 0.305, 0.025), 3):
    moved = predict(drift, mine)
    drop = float(
        np.sum(((locked - problem.rows[mine]) ** 2 - (moved - problem.rows[mine]) ** 2) * weight[in_mine])
    )
    movers = [
        f"{100 * problem.duty[i]:g}%"
        for i, m, lock in zip(mine, moved, locked, strict=True)
        if abs(m - lock) > 1e-6
    ]
    cut = [
        f"{100 * problem.duty[i]:g}%: {lock - m:.1f}"
        for i, m, lock in zip(checked, predict(drift, checked), locked_checked, strict=True)
    ]
    print(
        f"drift {drift:.3f}: moves fit videos {movers or 'none'}; weighted drop {drop:.2f}; validated videos cut by {cut}"
    )
