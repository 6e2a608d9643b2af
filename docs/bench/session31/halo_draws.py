"""The glare drawn for camsim's ``blinding_halo`` case per master seed, without rendering: the case's camera
(``case_camera``) and then the first draws of ``camsim.laser_blinding_pairs(halo=True)`` in its order (laser colour,
spot centre, the glare's scale, exponent and level a quarter of the diagonal out, the core's width, the peak power,
the reference capture's core fill). The order mirrors camsim at session 31; a change there breaks this script.

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/session31/halo_draws.py MASTER_SEED...``
"""

from __future__ import annotations

import importlib
import os
import sys

import numpy as np

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports


def main(seeds: list[str]) -> None:
    for seed in seeds:
        os.environ["CAMSIM_SEED"] = seed
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        _, rng, camera = sim.case_camera(sim.CASE_BY_NAME["blinding_halo"])
        colour = rng.choice(list(sim.cs.LASER_COLOURS))
        rng.uniform(0.3, 0.7, 2)  # the spot's centre
        scale, exponent = rng.uniform(3.0, 6.0), rng.uniform(1.5, 2.2)
        at_quarter = np.exp(rng.uniform(np.log(2e-3), np.log(8e-3)))
        core, peak, fill = rng.uniform(2.5, 4.0), rng.uniform(40, 120), rng.uniform(0.5, 0.9)
        print(
            f"{seed} {camera.tone} {colour} glare at a quarter diagonal {at_quarter:.4f} of the core's peak "
            f"(x peak power {at_quarter * peak:.3f}), exponent {exponent:.2f}, scale {scale:.1f} px, core {core:.2f} "
            f"px, peak power {peak:.0f}, core fill {fill:.2f}"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
