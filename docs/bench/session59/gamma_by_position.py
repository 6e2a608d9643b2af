"""A probe, not a rule: is a fitted tone curve the same at every position of the frame?

``python gamma_by_position.py CASE MASTER_SEED OUTDIR EFFECTS...`` from a checkout's root with ``PYTHONPATH=.``
renders camsim's light-projection ``CASE`` as ``test_independent_sim.py`` does under ``CAMSIM_SEED=MASTER_SEED``,
then fits each model in ``EFFECTS`` (effects joined by ``+``) on the calibration's fit pairs three times: on 800
pixels per pair drawn from the whole frame, from the half of the pixels nearest the frame's centre, and from the
half farthest from it, and prints the fitted parameters. A camera's tone curve acts on every pixel alike, so a
gamma that is the same in both halves and whole is the camera's; one that appears only when the halves are pooled
stands for something that changes across the frame. The last line of each model with a gamma compares the whole
frame's departure from 1 with the halves' mean departure (1 where the gamma is the same everywhere).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path.cwd() / "tests" / "calibration"))
sys.path.insert(1, str(Path.cwd() / "tests"))  # tests/sampling.py, which the case selection imports


def region_samples(problem, region: str, count: int = 800) -> list[torch.Tensor]:
    samples = []
    for index, pair in enumerate(problem.pairs):
        rows, cols = np.mgrid[0 : pair.height, 0 : pair.width]
        radius = np.hypot(
            (rows - (pair.height - 1) / 2) / pair.height, (cols - (pair.width - 1) / 2) / pair.width
        ).ravel()
        middle = np.median(radius)
        keep = {"whole": radius >= 0, "inner": radius <= middle, "outer": radius > middle}[region]
        pool = np.flatnonzero(keep)
        rng = np.random.default_rng(index)
        samples.append(torch.as_tensor(np.sort(rng.choice(pool, min(count, len(pool)), replace=False))))
    return samples


def main() -> None:
    name, master, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    os.environ["CAMSIM_SEED"] = master
    import camsim as cs
    import test_independent_sim as sim

    from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem, seeded_split

    case = sim.CASE_BY_NAME[name]
    seed, rng, camera = sim.case_camera(case)
    folder = out / f"{name}_seed{seed}"
    cs.write_pairs(folder / "pairs", case.render(rng, camera))
    cfg = CalibrateConfig(
        attack=case.attack, measured=str(folder / "pairs"), out=str(folder / "out"), seed=seed % 2**31
    )
    problem = build_problem(cfg)
    fit_items, _ = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
    print(
        f"{name} under master seed {master}: case seed {seed}, tone {camera.tone}, gamma {camera.tone_gamma:.3f}"
    )
    for effects in (frozenset(e.split("+")) for e in sys.argv[4:]):
        gammas = {}
        for region in ("whole", "inner", "outer"):
            problem.samples = region_samples(problem, region)
            fit = problem.fit(effects, fit_items)
            params = ", ".join(f"{k} {v:.3f}" for k, v in fit.params.items())
            print(f"  {'+'.join(sorted(effects))} | {region} | {params}")
            gammas[region] = fit.params.get("gamma")
        if gammas["whole"] is not None:
            halves = 0.5 * (gammas["inner"] + gammas["outer"]) - 1.0
            print(
                f"  pooled excess, (whole - 1) / (mean of the halves - 1): {(gammas['whole'] - 1.0) / halves:.2f}"
            )


if __name__ == "__main__":
    main()
