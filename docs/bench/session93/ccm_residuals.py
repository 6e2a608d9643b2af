"""Where the set-aside model errs on camsim's colour-correcting auto-exposure draws (as drawn): fit-pair residual
RMSE (grey levels) per channel, split by the laser capture's own channel (stored white: the capture's clipped core;
10-249: lit; under 10: dark) and by the attacked frame's stored value (0, 1-252, 253-255), with the matrix's takes
fitted free and pinned at the camera's (each column's mean off-diagonal, negated).

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python docs/bench/session93/ccm_residuals.py MASTER_SEED...``
"""

import os
import sys
import tempfile
from pathlib import Path

os.environ["CAMSIM_CCM"] = "1"

import numpy as np
import test_independent_sim as sim
import torch

from lerobot_phantom.calibration import core
from lerobot_phantom.calibration.frame_models import laser_blinding as model

EFFECTS = frozenset(
    {"linear_light_saturation", "auto_exposure", "tone_shoulder", "colour_correction", "frame_exposure"}
)
CASE = sim.CASE_BY_NAME["blinding_auto_exposure"]


def region_rmse(problem, fit, items) -> str:
    squares: dict[tuple[str, str], list[torch.Tensor]] = {}
    for i in map(int, items):
        pair = problem.pairs[i]
        residual = (255.0 * (problem.predict_registered(fit, i) - pair.attacked)) ** 2
        laser = 255.0 * pair.pattern[problem.laser_channel]
        stored = 255.0 * pair.attacked
        for c, channel in enumerate(model.CHANNELS):
            regions = {
                "capture white": laser >= 250,
                "capture lit": (laser >= 10) & (laser < 250),
                "stored 0": stored[c] <= 2,
                "stored mid": (stored[c] > 2) & (stored[c] < 253),
                "stored 255": stored[c] >= 253,
            }
            for name, mask in regions.items():
                squares.setdefault((channel, name), []).append(residual[c][mask])
    cells = {key: torch.cat(values) for key, values in squares.items()}
    return "\n".join(
        f"    {channel:5s} {name:13s} {float(v.mean().sqrt()):6.1f}  ({v.numel()} values)"
        for (channel, name), v in cells.items()
        if v.numel()
    )


for master in map(int, sys.argv[1:]):
    sim.MASTER_SEED = master
    seed = sim.case_seed(CASE)
    _, _, cam = sim.case_camera(CASE, seed)
    matrix = np.reshape(cam.ccm, (3, 3))
    takes = {
        f"ccm_{c}": float(-(matrix[:, j].sum() - matrix[j, j]) / 2) for j, c in enumerate(model.CHANNELS)
    }
    with tempfile.TemporaryDirectory() as tmp:
        problem, fit_items, _ = sim.drawn_split(CASE.name, seed, Path(tmp))
        print(master, "case seed", seed, cam.tone, "laser", model.CHANNELS[problem.laser_channel])
        free = problem.fit(EFFECTS, fit_items)
        print(
            "  takes free:",
            {k: round(free.params[k], 3) for k in takes},
            f"fit {problem.rmse(free, fit_items):.2f}",
        )
        print(region_rmse(problem, free, fit_items))
        specs = problem.param_specs
        problem.param_specs = lambda effects, specs=specs, takes=takes: [
            core.Param(p.name, takes[p.name], takes[p.name] - 1e-6, takes[p.name] + 1e-6, p.scale)
            if p.name in takes
            else p
            for p in specs(effects)
        ]
        pinned = problem.fit(EFFECTS, fit_items)
        print(
            "  takes at the camera's:",
            {k: round(v, 3) for k, v in takes.items()},
            f"fit {problem.rmse(pinned, fit_items):.2f}",
        )
        print(region_rmse(problem, pinned, fit_items), flush=True)
