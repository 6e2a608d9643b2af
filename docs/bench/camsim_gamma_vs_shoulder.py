"""Why light projection can name ``tone_shoulder`` instead of ``sensor_gamma`` on a power-law camera.

Usage: ``PYTHONPATH=. python docs/bench/camsim_gamma_vs_shoulder.py SEED...`` from the repository root. Each
master seed renders camsim's ``projection_sensor_gamma`` case as the test does, then again with one of camsim's
non-idealities removed (same draws otherwise), and fits in-sample on all pairs (the package's pixel sample)
additive light + reflectance under each tone form:

* ``gamma``: the ``sensor_gamma`` power law (free exponent);
* ``gamma@true``: the power law with its exponent fixed at the camera's;
* ``shoulder``: ``tone_shoulder`` (the log-logistic curve, no power law), the form selection compared with it.

Prints the RMSE in grey levels, the shoulder's share of the power law's RMSE (selection's margin asks < 0.95) and
the fitted parameters.
"""

from __future__ import annotations

import copy
import dataclasses
import importlib
import sys
import tempfile
from pathlib import Path

import torch
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.core import fit_least_squares
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.projection import projection_predict, projection_specs

NAME = "projection_sensor_gamma"
BASE = ("additive_light", "albedo_modulation")
VARIANTS = {
    "as drawn": {},
    "no wide PSF": {"psf_wide_share": 0.0},
    "no read noise": {"read_noise_e": 0.0},
    "JPEG 100": {"jpeg_quality": 100},
    "big well": {"full_well_e": 1e7},
}


def fit_in_sample(problem: ProjectionFrames, effects: tuple[str, ...], fixed: dict) -> tuple[float, dict]:
    items = range(len(problem.pairs))
    feats = [problem.features(i, problem.samples[i]) for i in items]
    stacked = {k: torch.cat([f[k] for f in feats]) for k in feats[0]}
    target = torch.cat([problem.pairs[i].attacked.reshape(3, -1)[:, problem.samples[i]].T for i in items])
    specs = [s for s in projection_specs(frozenset(effects)) if s.name not in fixed]

    def residuals(p: dict) -> torch.Tensor:
        p = {**p, **{k: torch.tensor(v, dtype=torch.float64) for k, v in fixed.items()}}
        predicted = projection_predict(
            stacked["surface"], stacked["projected"], stacked["strength"], effects, p
        )
        return (predicted - target).ravel()

    params = fit_least_squares(specs, residuals)
    with torch.no_grad():
        r = residuals({k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()})
    return 255.0 * float(r.pow(2).mean().sqrt()), {**params, **fixed}


def main() -> None:
    camsim = importlib.import_module("camsim")
    for master, _sim, case, seed, rng, camera in case_draws(NAME, [int(s) for s in sys.argv[1:]]):
        print(f"master {master} case seed {seed}: power law gamma {camera.tone_gamma:.3f}", flush=True)
        for label, change in VARIANTS.items():
            variant = dataclasses.replace(camera, **change)
            with tempfile.TemporaryDirectory() as scratch:
                camsim.write_pairs(Path(scratch) / "pairs", case.render(copy.deepcopy(rng), variant))
                problem = ProjectionFrames(load_pairs(Path(scratch) / "pairs", max_side=256), seed=0)
            gamma, gp = fit_in_sample(problem, (*BASE, "sensor_gamma"), {})
            true, _ = fit_in_sample(problem, (*BASE, "sensor_gamma"), {"gamma": camera.tone_gamma})
            shoulder, sp = fit_in_sample(problem, (*BASE, "tone_shoulder"), {})
            print(
                f"  {label:14s} gamma {gamma:5.2f} (exponent {gp['gamma']:.2f}, floor {gp['reflectance_floor']:.3f})"
                f"  gamma@true {true:5.2f}  shoulder {shoulder:5.2f} (s {sp['shoulder']:.2f}, n "
                f"{sp['shoulder_exponent']:.3f}, floor {sp['reflectance_floor']:.3f})  shoulder/gamma "
                f"{shoulder / gamma:.3f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
