"""The laser blinding attack built by ``transform_kwargs`` from a fit of one effect set on a camsim draw's fit pairs,
fed each held-out pair's capture, against that fit's prediction: RMS and largest difference in grey levels, and
both held-out RMSEs; with ``--ccm`` on a colour-correcting camera (``CAMSIM_CCM=1``), also with ``raw_colour=None``
(the capture's stored channels taken as raw light, the attack before session 92).

Usage: ``CAMSIM_SEED=0 PYTHONPATH=TREE:TREE/tests/calibration:TREE/tests python docs/bench/session92/attack_fit_parity.py
CASE CASE_SEED EFFECT,EFFECT... [--ccm]``
"""

import os
import sys
import tempfile
from pathlib import Path

if "--ccm" in sys.argv:
    os.environ["CAMSIM_CCM"] = "1"

import test_independent_sim as sim
import torch

from lerobot_phantom.transforms.laser_blinding import LaserBlinding


def main() -> None:
    name, seed, effects = sys.argv[1], int(sys.argv[2]), frozenset(sys.argv[3].split(","))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        problem, fit_items, heldout = sim.drawn_split(name, seed, folder)
        fit = problem.fit(effects, fit_items)
        options = problem.transform_kwargs(fit)
        variants = {"as written": {}}
        if "--ccm" in sys.argv:
            variants["raw_colour=None"] = {"raw_colour": None}
        for label, changes in variants.items():
            apart, attack_errors, fit_errors = [], [], []
            for i in heldout:
                pair = problem.pairs[int(i)]
                capture = str(folder / f"pattern_{int(i):03d}.png")
                attack = LaserBlinding(pair.intensity, pattern=capture, **{**options, **changes})
                attacked = attack(pair.clean.unsqueeze(0).float())[0].double()
                predicted = problem.predict_pair(fit, int(i))
                apart.append((attacked - predicted).ravel())
                attack_errors.append((attacked - pair.attacked).ravel())
                fit_errors.append((predicted - pair.attacked).ravel())
            apart = 255 * torch.cat(apart)
            print(
                f"{name} {seed} {sorted(effects)} {label}: attack against the fit RMS "
                f"{float(apart.pow(2).mean().sqrt()):.3g}, largest {float(apart.abs().max()):.3g}; held-out RMSE "
                f"attack {255 * float(torch.cat(attack_errors).pow(2).mean().sqrt()):.2f}, fit "
                f"{255 * float(torch.cat(fit_errors).pow(2).mean().sqrt()):.2f}"
            )


if __name__ == "__main__":
    main()
