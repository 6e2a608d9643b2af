"""How well the ultrasound blur attack that ``calibrated.json`` builds predicts a camera's held-out frames, beside
the calibration's own fit: camsim blur draws (tests/calibration/test_independent_sim.py) split as the CLI splits
them, fitted with the effects given, and ``UltrasoundBlur(**transform_kwargs(fit))`` applied to each held-out clean
frame along the fitted displacement at that frame's intensity (calibration_testkit.blurred_by_the_attack). RMSE in
grey levels. Run it in two checkouts to compare their attacks (the fit is the same in both).

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python docs/bench/session87/blur_attack_heldout.py
EFFECT[,EFFECT...] CASE:CASE_SEED...``
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import torch


def main() -> None:
    import test_independent_sim as sim
    from calibration_testkit import blurred_by_the_attack

    from lerobot_phantom.transforms.ultrasound_blur import UltrasoundBlur

    torch.set_num_threads(1)
    effects = frozenset(sys.argv[1].split(","))
    for draw in sys.argv[2:]:
        name, seed = draw.split(":")
        with tempfile.TemporaryDirectory() as folder:
            problem, fit_items, heldout = sim.drawn_split(name, int(seed), Path(folder))
        fit = problem.fit(effects, fit_items)
        kwargs = problem.transform_kwargs(fit)
        attack = UltrasoundBlur(**kwargs)
        errors = {"fit": [], "attack": []}
        for i in heldout:
            attacked = problem.pairs[int(i)].attacked
            errors["fit"].append(problem.predict_pair(fit, int(i)) - attacked)
            errors["attack"].append(blurred_by_the_attack(attack, problem, fit, int(i)) - attacked)
        rmse = {
            k: 255 * float(torch.cat([e.ravel() for e in v]).pow(2).mean().sqrt()) for k, v in errors.items()
        }
        print(
            f"{name} case seed {seed}, {len(heldout)} held-out pairs, {sorted(effects)}, kwargs {kwargs}: fit "
            f"{rmse['fit']:.2f}, attack {rmse['attack']:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
