"""A camsim blinding_halo draw's inner folds (the calibration's own split and selection folds): the fitted
parameters and validation RMSE of linear light + shoulder, without and with the halo, per fold.

usage: PYTHONPATH=. python docs/bench/session65/halo_folds.py CASE_DIR   (holding pairs/ and out/report.json, as
docs/bench/session64/run_camsim_case.py writes them)
"""

import json
import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import seeded_split, selection_folds, single_threaded


def main() -> None:
    folder = Path(sys.argv[1])
    seed = json.loads((folder / "out" / "report.json").read_text())["split"]["seed"]
    cfg = CalibrateConfig(
        attack="laser_blinding", measured=str(folder / "pairs"), out=str(folder / "unused"), seed=seed
    )
    problem = build_problem(cfg)
    fit_items, _ = seeded_split(problem.n_items, cfg.heldout, seed)
    with single_threaded():
        for extra in ((), ("halo_power_law",)):
            effects = frozenset({"linear_light_saturation", "tone_shoulder", *extra})
            for k, (train, left_out) in enumerate(selection_folds(fit_items, 4, seed)):
                fit = problem.fit(effects, train)
                squared, count = problem.squared_errors(fit, left_out)
                shown = {n: round(v, 3) for n, v in fit.params.items() if not n.startswith("background")}
                print(
                    f"{'+'.join(extra) or 'no halo'} fold {k}: validation RMSE {np.sqrt(squared / count):.3f} {shown}"
                )


if __name__ == "__main__":
    main()
