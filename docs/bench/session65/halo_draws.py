"""The glare camsim's blinding_halo case plants on given master seeds: the draws of ``camsim.laser_blinding_pairs``
(halo=True) replayed in its order from where the test's camera draws leave the generator (nothing is rendered).

usage: PYTHONPATH=. python docs/bench/session65/halo_draws.py SEED...
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws


def main() -> None:
    import camsim as cs

    for master, _sim, _case, _seed, rng, _cam in case_draws("blinding_halo", [int(s) for s in sys.argv[1:]]):
        colour = rng.choice(list(cs.LASER_COLOURS))
        rng.uniform(size=2)  # the spot's centre
        scale_px, exponent = rng.uniform(3.0, 6.0), rng.uniform(1.5, 2.2)
        at_quarter = np.exp(rng.uniform(np.log(2e-3), np.log(8e-3)))
        rng.uniform(2.5, 4.0)  # the core's width
        peak_power = rng.uniform(40, 120)
        print(
            f"{master}: {colour} laser, glare a quarter diagonal out {1e3 * at_quarter:.2f} per mille of the core's "
            f"peak (exponent {exponent:.2f}, scale {scale_px:.1f} px), peak power {peak_power:.0f} full wells per unit "
            f"exposure: glare there at intensity 1 {at_quarter * peak_power:.3f} full wells"
        )


if __name__ == "__main__":
    main()
