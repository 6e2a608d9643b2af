"""The calibrated laser strip attack against the stripe model, pair by pair: a camsim draw split as the CLI splits
it, the stripe fitted with the effects given on the fit pairs, and on each held-out pair the attack
(``LaserColorStrip(**transform_kwargs(fit))``) at the pair's intensity and at the pulse phase registered on it,
beside ``predict_stripe`` at that phase: each one's RMSE against the attacked frame and their largest difference,
in grey levels.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python
docs/bench/session87/strip_attack_at_registered_phase.py CASE CASE_SEED EFFECT[,EFFECT...]``
"""

import sys
import tempfile
from pathlib import Path

import torch

from lerobot_phantom.transforms.laser_color_strip import LaserColorStrip


def main() -> None:
    import test_independent_sim as sim

    name, seed, effects = sys.argv[1], int(sys.argv[2]), frozenset(sys.argv[3].split(","))
    with tempfile.TemporaryDirectory() as folder:
        problem, fit_items, heldout = sim.drawn_split(name, seed, Path(folder))
        camera = sim.case_camera(sim.CASE_BY_NAME[name], seed)[2]
    fit = problem.fit(effects, fit_items)
    kwargs = problem.transform_kwargs(fit)
    print(f"{name} case seed {seed} ({camera.tone}), {sorted(effects)}; kwargs {kwargs}")
    attack = LaserColorStrip(**kwargs)
    for i in heldout:
        pair = problem.pairs[int(i)]
        phase = problem.best_phase(fit.params, int(i))
        model = problem.predict_stripe(fit.params, int(i), phase)
        params = attack.sample_params(
            1, pair.height, pair.width, intensity=torch.tensor([pair.intensity], dtype=torch.float64)
        )
        params["phase_s"] = torch.tensor([phase / pair.height], dtype=torch.float64)
        out = attack.apply_params(pair.clean.unsqueeze(0), params)[0]
        print(
            f"pair {int(i)} ({pair.height} rows, intensity {pair.intensity:.3f}), phase {phase:g} rows: model "
            f"{255 * float((model - pair.attacked).pow(2).mean().sqrt()):.2f}, attack "
            f"{255 * float((out - pair.attacked).pow(2).mean().sqrt()):.2f}, largest difference "
            f"{255 * float((out - model).abs().max()):.2e}"
        )


if __name__ == "__main__":
    main()
