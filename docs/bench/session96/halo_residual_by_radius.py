"""camsim's blinding_halo case: the signed residual (attacked minus predicted, grey levels) of fitted models by the
distance from the spot, where the capture measured the laser's light and where it did not (session 96).

Usage: ``PYTHONPATH=. python docs/bench/session96/halo_residual_by_radius.py PAIRS_DIR SPLIT_SEED EFFECTS...``
(as ``halo_fits.py``); fitted on the fit pairs, the residual pooled over them, the three channels apart.
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from halo_fits import case_problem

EDGES_REF_PX = (0, 20, 40, 60, 80, 100, 120, 150, 200, 400)


def main() -> None:
    problem, fit_items, _ = case_problem(Path(sys.argv[1]), int(sys.argv[2]))
    for group in sys.argv[3:]:
        fit = problem.fit(frozenset(group.split("+")), fit_items)
        residual, radius, unmeasured = [], [], []
        for i in map(int, fit_items):
            pair = problem.pairs[i]
            residual.append((255.0 * (pair.attacked - problem.predict_pair(fit, i))).reshape(3, -1).numpy())
            f = problem.features(i, None)
            radius.append(f["radius"].reshape(-1).numpy())
            unmeasured.append(f["unmeasured"].reshape(-1).numpy() > 0)
        residual, radius, unmeasured = (
            np.concatenate(residual, 1),
            np.concatenate(radius),
            np.concatenate(unmeasured),
        )
        print(f"{group}: {{{', '.join(f'{k}: {v:.4g}' for k, v in fit.params.items())}}}")
        for lo, hi in itertools.pairwise(EDGES_REF_PX):
            ring = (radius >= lo) & (radius < hi)
            cells = []
            for where, mask in (("measured", ring & ~unmeasured), ("unmeasured", ring & unmeasured)):
                if mask.sum():
                    means = ", ".join(f"{residual[c, mask].mean():+.2f}" for c in range(3))
                    cells.append(f"{where} {int(mask.sum())} px mean R,G,B {means}")
            print(f"  {lo}-{hi} ref px: " + "; ".join(cells))


if __name__ == "__main__":
    main()
