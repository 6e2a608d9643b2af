"""One camsim case draw: effect sets scored as selection scores them (the 4 inner folds of the
fit pairs, from the defaults), with the members a fold fit pins at a bound, and fitted on all fit pairs: fit and
held-out RMSE (grey levels), and the reflectance floor, the shoulder's knee exponent and the gamma. Usage:
``[CAMSIM_CCM=1] CAMSIM_SEED=1 PYTHONPATH=.:tests/calibration:tests python docs/bench/session98/structures.py CASE
CASE_SEED SET...`` (a set: effect names joined by ``+``; CAMSIM_SEED only lets the test module import: the case seed is
given). The fits run on one thread, as ``calibrate`` runs them: on two they end elsewhere (12.168 for 12.125,
docs/bench/session101/structures_threads_e38c879.txt)."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import test_independent_sim as sim

from lerobot_phantom.calibration import core


def main() -> None:
    name, seed, sets = sys.argv[1], int(sys.argv[2]), [frozenset(s.split("+")) for s in sys.argv[3:]]
    with tempfile.TemporaryDirectory() as folder:
        problem, fit_items, heldout = sim.drawn_split(name, seed, Path(folder))
        splits = core.selection_folds(fit_items, 4, seed % 2**31, 2500)
        print(f"{name}, case seed {seed}")
        for effects in sets:
            score, fold_fits, _ = core.cross_validated(problem, effects, splits, None)
            pinned = core.pinned_members(problem, effects, effects, fold_fits)
            fit = problem.fit(effects, fit_items)
            shown = {
                k: round(fit.params[k], 3)
                for k in ("reflectance_floor", "shoulder_exponent", "gamma")
                if k in fit.params
            }
            print(
                f"  {'+'.join(sorted(effects))}: cross-validated {score:.3f}, fit {problem.rmse(fit, fit_items):.3f}, "
                f"held-out {problem.rmse(fit, heldout):.3f}; pinned {pinned or 'none'}; {shown}",
                flush=True,
            )


if __name__ == "__main__":
    with core.single_threaded():
        main()
