"""Why ``albedo_modulation`` goes unnamed on camsim's ``projection_crosstalk`` case under filmic cameras.

Usage: ``PYTHONPATH=. python docs/bench/camsim_projection_tone_oracle.py TESTS_DIR SEED...``
(TESTS_DIR holds ``test_independent_sim.py`` and ``camsim.py``.) Each master seed renders the case exactly as the
test does and fits nested light-projection models in-sample on all its pairs (the package's pixel sample):

* ``library``: the frames as stored, decoded by the fitted ``sensor_gamma`` (the model the selection sees);
* ``+ level``: the same with a free light level per pair (pair 0 fixed at 1), the "per-scene light" hypothesis;
* ``shoulder``: the frames as stored, decoded by the package's shoulder curve (``tone_shoulder``, under a gamma);
* ``oracle``: the frames linearised with camsim's own tone curve and the emitted pattern with the projector's 2.2,
  so the model composes true linear light (RMSE in linear units x 255, not comparable with the rows above).

For each model: the RMSE, the reflectance floor (0 = full modulation, 2 = the end of its range, where modulation
has all but vanished) and the spread of the per-pair levels.
"""

from __future__ import annotations

import importlib
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.core import Param, fit_least_squares
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.projection import projection_predict, projection_specs

NAME = "projection_crosstalk"
PROJECTOR_GAMMA = 2.2  # camsim's projector: light = frame ** 2.2
BASE = ("additive_light", "channel_crosstalk")


def linearise(image: torch.Tensor, camsim, camera) -> torch.Tensor:
    """Pixel values -> linear light through the inverse of camsim's tone curve (a dense table)."""
    grid = np.linspace(0.0, 1.0, 20001)
    encoded = camsim.tone_curve(grid, camera)
    return torch.from_numpy(np.interp(image.numpy(), encoded, grid))


def fit_in_sample(problem: ProjectionFrames, effects: tuple[str, ...], levels: bool) -> tuple[float, dict]:
    items = range(len(problem.pairs))
    feats = [problem.features(i, problem.samples[i]) for i in items]
    stacked = {k: torch.cat([f[k] for f in feats]) for k in feats[0]}
    sizes = torch.tensor([len(f["surface"]) for f in feats])
    target = torch.cat([problem.pairs[i].attacked.reshape(3, -1)[:, problem.samples[i]].T for i in items])
    level_names = [f"level_{k}" for k in range(1, len(feats))] if levels else []
    specs = projection_specs(frozenset(effects)) + [Param(n, 1.0, 0.1, 10.0, scale=0.3) for n in level_names]

    def residuals(p: dict) -> torch.Tensor:
        strength = stacked["strength"]
        if levels:
            per_pair = torch.stack([torch.ones((), dtype=torch.float64), *(p[n] for n in level_names)])
            strength = strength * torch.repeat_interleave(per_pair, sizes)[:, None]
        predicted = projection_predict(
            stacked["surface"], stacked["projected"], strength, frozenset(effects), p
        )
        return (predicted - target).ravel()

    params = fit_least_squares(specs, residuals)
    with torch.no_grad():
        r = residuals({k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()})
    return 255.0 * float(r.pow(2).mean().sqrt()), params


def describe(label: str, effects: tuple[str, ...], rmse: float, params: dict) -> str:
    parts = [f"{label:8s} {'+'.join(e for e in effects if e not in BASE) or '-':32s} RMSE {rmse:5.2f}"]
    if "reflectance_floor" in params:
        parts.append(f"floor {params['reflectance_floor']:.2f}")
    for name in ("gamma", "shoulder", "shoulder_exponent"):
        if name in params:
            parts.append(f"{name} {params[name]:.2f}")
    levels = [1.0] + [v for k, v in params.items() if k.startswith("level_")]  # pair 0's level is fixed at 1
    if len(levels) > 1:
        parts.append(f"levels {min(levels):.2f}-{max(levels):.2f}")
    return "  " + ", ".join(parts)


def main() -> None:
    tests_dir, seeds = sys.argv[1], [int(s) for s in sys.argv[2:]]
    sys.path.insert(0, tests_dir)
    camsim = importlib.import_module("camsim")
    for master, _sim, case, seed, rng, camera in case_draws(NAME, seeds):
        with tempfile.TemporaryDirectory() as scratch:
            camsim.write_pairs(Path(scratch) / "pairs", case.render(rng, camera))
            pairs = load_pairs(Path(scratch) / "pairs", max_side=256)  # the CLI's default working size
        print(f"master {master} case seed {seed}: tone {camera.tone}", flush=True)
        stored = ProjectionFrames(pairs, seed=0)
        for levels in (False, True):
            for extra in (("sensor_gamma",), ("albedo_modulation", "sensor_gamma")):
                effects = BASE + extra
                label = "+ level" if levels else "library"
                print(describe(label, effects, *fit_in_sample(stored, effects, levels)), flush=True)
        for extra in (
            ("tone_shoulder", "sensor_gamma"),
            ("albedo_modulation", "tone_shoulder", "sensor_gamma"),
        ):
            print(describe("shoulder", BASE + extra, *fit_in_sample(stored, BASE + extra, False)), flush=True)
        for pair in pairs:
            pair.clean = linearise(pair.clean, camsim, camera)
            pair.attacked = linearise(pair.attacked, camsim, camera)
            pair.pattern = pair.pattern**PROJECTOR_GAMMA
        linear = ProjectionFrames(pairs, seed=0)
        for levels in (False, True):
            for extra in ((), ("albedo_modulation",)):
                label = "oracle+L" if levels else "oracle"
                print(describe(label, BASE + extra, *fit_in_sample(linear, BASE + extra, levels)), flush=True)


if __name__ == "__main__":
    main()
