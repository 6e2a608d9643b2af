"""How much camsim's planted reflectance term changes the frames of the ``projection_crosstalk`` case, per camera
tone curve: the case rendered as the test renders it for a master seed, and again from the same generator state
with every surface returning the projector's light as the scene's mean reflectance would
(``camsim.light_projection_pairs(reflectance_modulated=False)``; every noise draw the same). Prints, per seed, the
RMS difference of the attacked frames in grey levels (what the reflectance term can at most explain) next to the
RMS of attacked minus clean (the attack's own size).

Usage: ``PYTHONPATH=. python docs/bench/session32/albedo_size.py SEED...`` from the repository root.
"""

from __future__ import annotations

import copy
import functools
import os
import sys

import numpy as np

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports
os.environ.setdefault("CAMSIM_SEED", "0")  # the module reads one at import; each seed below replaces it

import camsim as cs
import test_independent_sim as sim

CASE = sim.CASE_BY_NAME["projection_crosstalk"]


def rms(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a.astype(float) - b.astype(float)) ** 2)))


def main(seeds: list[str]) -> None:
    rendered = cs.light_projection_pairs
    for seed in seeds:
        sim.MASTER_SEED = int(seed)
        _, rng, camera = sim.case_camera(CASE)
        twin = copy.deepcopy(rng)
        modulated = CASE.render(rng, camera)
        cs.light_projection_pairs = functools.partial(rendered, reflectance_modulated=False)
        try:
            uniform = CASE.render(twin, camera)
        finally:
            cs.light_projection_pairs = rendered
        change = np.mean([rms(a.attacked, b.attacked) for a, b in zip(modulated, uniform, strict=True)])
        attack = np.mean([rms(p.attacked, p.clean) for p in modulated])
        print(
            f"{seed} {camera.tone}: reflectance term changes the attacked frames by {change:.2f} grey levels RMS "
            f"(attack itself {attack:.2f}; {100 * change / attack:.0f}%)"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
