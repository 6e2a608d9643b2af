"""Oracles for the colour-correcting camera's auto-exposure misses (session 71's defect: the matrix's take of one
channel at its bound 1): camsim's ``blinding_auto_exposure`` draws at the master seeds given, rendered with parts of
the camera replaced, and the set-aside model (``PROBE_EFFECTS``) fitted on each draw's fit pairs three ways:

* ``free``: as the calibration fits it;
* ``camera``: the takes ``ccm_<channel>`` pinned at the camera's (each column's mean off-diagonal, negated);
* ``exact``: camsim's own six-entry matrix in place of the column form (the takes then unused).

Each line gives the fitted parameters and the RMSE (grey levels) over the fit pairs and the held-out pairs.

Knobs (environment): ``PROBE_EFFECTS`` the model's effects, comma-separated; ``PROBE_CAMERA`` JSON of
``camsim.Camera`` fields to replace (``{"full_well_e": 1e9, "read_noise_e": 0, "jpeg_quality": 100}`` is a noiseless
camera, ``"ccm": null`` one without a matrix); ``PROBE_GREY=1`` every scene's reflectance grey (each pixel's channel
mean: no clean frame holds a channel the matrix pushes below 0 or above white); ``PROBE_NO_MOSAIC=1`` every channel
sampled at every pixel (no Bayer mosaic, no demosaic); ``PROBE_UNSATURATED=1`` the laser captured at the halo case's
50-90% core fill without its glare (the capture measures the beam's core); ``PROBE_UNIFORM_METER=1`` camsim meters
the channel mean over every pixel alike (the model's meter form) instead of centre-weighted luminance.

Usage: ``PROBE_EFFECTS=... CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python
docs/bench/session93/ccm_oracles.py MASTER_SEED...``
"""

import dataclasses
import json
import os
import sys
import tempfile
from pathlib import Path

os.environ["CAMSIM_CCM"] = "1"

import camsim as cs
import numpy as np
import test_independent_sim as sim
import torch

from lerobot_phantom.calibration import core
from lerobot_phantom.calibration.frame_models import laser_blinding as model

EFFECTS = frozenset(os.environ["PROBE_EFFECTS"].split(","))
CAMERA = json.loads(os.environ.get("PROBE_CAMERA", "{}"))
KNOBS = ("PROBE_GREY", "PROBE_NO_MOSAIC", "PROBE_UNSATURATED", "PROBE_UNIFORM_METER")
ON = {knob: os.environ.get(knob) == "1" for knob in KNOBS}
CASE = sim.CASE_BY_NAME["blinding_auto_exposure"]


def uniform_meter(irradiance: np.ndarray, cam: cs.Camera) -> float:
    """camsim's meter with every pixel weighted alike and the channel mean for its luminance."""
    light = irradiance.mean(-1)
    low, high = np.log(1e-4), np.log(1e3)
    for _ in range(40):
        mid = (low + high) / 2
        if np.minimum(np.exp(mid) * light, 1.0).mean() < cam.exposure_target:
            low = mid
        else:
            high = mid
    return float(np.exp((low + high) / 2))


if ON["PROBE_UNSATURATED"]:
    spot = cs.laser_spot
    cs.laser_spot = lambda cam, centre, colour, *, core_px, halo: spot(
        cam, centre, colour, core_px=core_px, halo=None
    )
    sim.CASE_BY_NAME[CASE.name] = dataclasses.replace(
        CASE, render=lambda rng, cam: cs.laser_blinding_pairs(rng, cam, sim.N_PAIRS, halo=True)
    )
if ON["PROBE_NO_MOSAIC"]:
    cs.mosaic = lambda linear: linear.copy()
    cs.demosaic = lambda raw: raw
if ON["PROBE_GREY"]:
    reflectance = cs.scene_reflectance
    cs.scene_reflectance = lambda *a: np.repeat(reflectance(*a).mean(-1, keepdims=True), 3, axis=-1)
if ON["PROBE_UNIFORM_METER"]:
    cs.meter = uniform_meter
drawn_camera = sim.case_camera


def replaced_camera(case, seed=None):
    seed, rng, cam = drawn_camera(case, seed)
    return seed, rng, dataclasses.replace(cam, **CAMERA)


sim.case_camera = replaced_camera


def pinned(specs, values: dict[str, float]):
    def param_specs(effects):
        return [
            core.Param(p.name, values[p.name], values[p.name] - 1e-6, values[p.name] + 1e-6, p.scale)
            if p.name in values
            else p
            for p in specs(effects)
        ]

    return param_specs


def rounded(params: dict[str, float]) -> dict[str, float]:
    return {k: round(v, 3) for k, v in params.items()}


print("camera", CAMERA, "knobs", [k for k in KNOBS if ON[k]], "effects", sorted(EFFECTS))
for master in map(int, sys.argv[1:]):
    sim.MASTER_SEED = master
    seed = sim.case_seed(CASE)
    _, _, cam = sim.case_camera(CASE, seed)
    matrix = np.eye(3) if cam.ccm is None else np.reshape(cam.ccm, (3, 3))
    takes = {
        f"ccm_{c}": float(-(matrix[:, j].sum() - matrix[j, j]) / 2) for j, c in enumerate(model.CHANNELS)
    }
    with tempfile.TemporaryDirectory() as tmp:
        problem, fit_items, heldout = sim.drawn_split(CASE.name, seed, Path(tmp))
        laser = model.CHANNELS[problem.laser_channel]
        print(master, "case seed", seed, cam.tone, "laser", laser, "camera's takes", rounded(takes))
        column_form = model.correction_matrix
        try:
            for label in ("free", "camera", "exact") if cam.ccm is not None else ("free",):
                if label == "camera":
                    problem.param_specs = pinned(problem.param_specs, takes)
                if label == "exact":
                    model.correction_matrix = lambda params, m=matrix: torch.as_tensor(m, dtype=torch.float64)
                fit = problem.fit(EFFECTS, fit_items)
                fit_rmse, held_rmse = problem.rmse(fit, fit_items), problem.rmse(fit, heldout)
                print(
                    f"  {label:6s} {rounded(fit.params)} fit {fit_rmse:.2f} held {held_rmse:.2f}", flush=True
                )
        finally:
            model.correction_matrix = column_form
