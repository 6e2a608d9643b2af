"""The laser blinding attack ``calibrated.json`` builds, fed each held-out pair's capture, against the model the
calibration wrote (its report's parameters, not a refit): a camsim draw calibrated by ``lerobot-phantom-calibrate``
(``session88/calibrated_draws.py``), then ``make_attack("laser_blinding", intensity=s, calibration=OUT,
pattern=<the pair's capture>, exposure_spread=0)`` on each held-out clean frame against the written model at the
median exposure (``exposure_spread`` 0): RMS and largest difference in grey levels, and the share of pixels more
than one grey level apart. Session 89's bench compared the attack with a fit made again from cold starts, which on
colour-correcting auto-exposure draws ends elsewhere than the calibration's (the parameters' largest relative
difference is printed too).

Usage: ``[CAMSIM_CCM=1] CAMSIM_SEED=0 PYTHONPATH=TREE:TREE/tests/calibration:TREE/tests:docs/bench/session88 python
docs/bench/session92/blinding_attack_parity.py CASE:CASE_SEED...``
"""

from __future__ import annotations

import sys

import numpy as np
import torch
from calibrated_draws import calibrated_draws


def main() -> None:
    from lerobot_phantom.calibration.core import Fit
    from lerobot_phantom.transforms.registry import make_attack

    for draw in calibrated_draws("laser_blinding", sys.argv[1:]):
        problem, extended = draw.problem, draw.report["extended"]
        written = Fit(frozenset(extended["effects"]), {**extended["params"], "exposure_spread": 0.0})
        written.extra["items"] = np.asarray(draw.fit_items)
        refit = draw.fit()
        moved = max(
            (abs(v - refit.params[k]) / max(abs(v), 1e-12) for k, v in extended["params"].items()),
            default=0.0,
        )
        apart = []
        for i in draw.heldout:
            pair = problem.pairs[int(i)]
            capture = str(draw.folder / "pairs" / f"pattern_{int(i):03d}.png")  # camsim.write_pairs' names
            attack = make_attack(
                "laser_blinding",
                intensity=pair.intensity,
                calibration=str(draw.out),
                pattern=capture,
                exposure_spread=0.0,
            )
            attacked = attack(pair.clean.unsqueeze(0).float())[0].double()
            apart.append(255 * (attacked - problem.predict_pair(written, int(i))).ravel())
        apart = torch.cat(apart) if apart else torch.zeros(1)
        print(
            f"{draw.name} case seed {draw.seed}, {len(draw.heldout)} held-out pairs, written "
            f"{sorted(extended['effects'])}, meter power {extended['params'].get('auto_exposure', 0.0):.4g}: attack "
            f"against the written model at the median exposure RMS {float(apart.pow(2).mean().sqrt()):.3f}, largest "
            f"{float(apart.abs().max()):.2f}, share over 1 grey level {float((apart.abs() > 1).double().mean()):.4f}; "
            f"a cold refit's parameters moved by up to {moved:.3g} (relative)",
            flush=True,
        )


if __name__ == "__main__":
    main()
