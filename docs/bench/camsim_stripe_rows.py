"""What a camsim laser-strip case's frames hold, row by row: the attacked frame minus the clean one, averaged over
the width and summed over the channels, in hundredths of full scale (uint8 frames as the calibration reads them).

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/camsim_stripe_rows.py CASE SEED...`` from the repository root
(the case rendered exactly as ``tests/calibration/test_independent_sim.py`` does for that master seed). Under a
tone curve, stripes of equal light raise dark and bright rows by different amounts.
"""

from __future__ import annotations

import sys

import numpy as np

sys.path.insert(0, "docs/bench")
from camsim_case_batch import cases_per_master_seed


def main() -> None:
    name, seeds = sys.argv[1], sys.argv[2:]
    for seed, sim, case in cases_per_master_seed(name, seeds):
        _, rng, camera = sim.case_camera(case)
        print(f"{name} {seed} tone {camera.tone}")
        for i, pair in enumerate(case.render(rng, camera)):
            added = (pair.attacked.astype(np.float64) - pair.clean.astype(np.float64)) / 255.0  # (H, W, 3)
            rows = added.mean(axis=1).sum(axis=1)
            print(
                f"  pair {i} intensity {pair.intensity:.2f}: " + " ".join(f"{round(100 * v):d}" for v in rows)
            )


if __name__ == "__main__":
    main()
