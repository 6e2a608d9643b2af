"""True laser gain of camsim's blinding_halo case per master seed: the attack's power per unit intensity over the
power the laser pattern was captured at, read from the irradiance camsim hands its capture at the spot's peak.
usage: python halo_true_gains.py SEED..."""

import importlib
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
sys.path.insert(
    1, str(Path(__file__).resolve().parents[3] / "tests")
)  # tests/sampling.py, which the case selection imports
import camsim as cs

REAL_SPOT, REAL_CAPTURE = cs.laser_spot, cs.capture


def true_gain(master: int) -> str:
    os.environ["CAMSIM_SEED"] = str(master)
    sys.modules.pop("test_independent_sim", None)
    sim_test = importlib.import_module("test_independent_sim")
    spots, irradiances = [], []

    def spot(*args, **kwargs):
        spots.append(REAL_SPOT(*args, **kwargs))
        return spots[-1]

    def capture(irradiance, cam, rng, exposure=None):
        irradiances.append(irradiance)
        return REAL_CAPTURE(irradiance, cam, rng, exposure=exposure)

    cs.laser_spot, cs.capture = spot, capture
    case = sim_test.CASE_BY_NAME["blinding_halo"]
    seed, rng, cam = sim_test.case_camera(case)
    pairs = case.render(rng, cam)
    profile = spots[0]
    peak = np.unravel_index(np.argmax(profile.sum(-1)), profile.shape[:2])
    power = [irradiance[peak].max() / profile[peak].max() for irradiance in irradiances]
    # captures in order: clean 0, the pattern, attacked 0, clean 1, attacked 1, ...
    reference = power[1]
    attack = np.median([p / pair.intensity for p, pair in zip(power[2::2], pairs, strict=True)])
    return (
        f"master {master} case seed {seed} tone {cam.tone} ae {cam.auto_exposure}: reference {reference:.4g}, "
        f"attack power/intensity {attack:.4g}, gain {attack / reference:.4g}, log10 {np.log10(attack / reference):.3f}"
    )


for master in (int(s) for s in sys.argv[1:]):
    print(true_gain(master), flush=True)
