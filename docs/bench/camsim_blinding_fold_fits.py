"""The base and linear light + auto-exposure on one camsim laser blinding case: fitted on all pairs, then in each
inner fold of the CLI's selection (its split and fold seeds), with each pair's RMSE.

Usage: ``PYTHONPATH=. python docs/bench/camsim_blinding_fold_fits.py PAIRS_DIR CASE_SEED`` (a case's ``pairs``
folder under a camsim run's basetemp, and the case seed its report was calibrated with).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import kfold, seeded_split
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames

MODELS = (frozenset(), frozenset({"linear_light_saturation", "auto_exposure"}))


def describe(problem: BlindingFrames, fit) -> str:
    per_pair = [problem.rmse(fit, np.array([i])) for i in range(problem.n_items)]
    params = {k: round(v, 3) for k, v in fit.params.items()}
    return f"{params} per pair {np.round(per_pair, 1).tolist()}"


def main() -> None:
    folder, seed = Path(sys.argv[1]), int(sys.argv[2]) % 2**31
    defaults = CalibrateConfig()
    problem = BlindingFrames(load_pairs(folder, max_side=defaults.max_side), seed)
    every = np.arange(problem.n_items)
    print("intensities", [round(p.intensity, 2) for p in problem.pairs])
    for effects in MODELS:
        fit = problem.fit(effects, every)
        print(
            f"all pairs {'+'.join(sorted(effects)) or 'base'}: {problem.rmse(fit, every):.2f}; {describe(problem, fit)}"
        )
    fit_items, _ = seeded_split(problem.n_items, defaults.heldout, seed)
    # forward_select's folds: seed + 1 and its default cap on training items
    for train, val in kfold(fit_items, defaults.folds, seed + 1, 2500):
        for effects in MODELS:
            fit = problem.fit(effects, train)
            print(
                f"fold train {train.tolist()} val {val.tolist()} {'+'.join(sorted(effects)) or 'base'}: "
                f"train {problem.rmse(fit, train):.2f} val {problem.rmse(fit, val):.2f}; {describe(problem, fit)}"
            )


if __name__ == "__main__":
    main()
