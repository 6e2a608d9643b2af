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
the channel mean over every pixel alike (the model's meter form) instead of centre-weighted luminance;
``PROBE_UNIFORM_LUMA_METER=1`` (session 95) camsim meters luminance over every pixel alike (its weighting replaced);
``PROBE_CENTRED_MEAN_METER=1`` (session 95) camsim meters the channel mean, centre-weighted (its luminance replaced);
``PROBE_CORE_UNSCORED=1`` (session 94) the fit scores no fainter channel inside the laser channel's white core of the
capture (its predictions there replaced by the frame's values, in fits only; the RMSEs printed score every channel);
``PROBE_CORE_PROFILED=1`` (session 94) the fit reads the beam's light at each pixel of that core as the value, on a
grid of ``PROFILE_STEPS`` from 0.01 to 3000 times a full well (and the Gaussian continuation's own), whose
prediction of all three channels lies nearest the frame's in linear light (a nuisance profiled out; in fits only);
``PROBE_NO_BLOOM=1`` (session 94) camsim's laser spot without its bloom (its Gaussian core alone; the lens's point
spread, ``psf_wide_share`` of ``PROBE_CAMERA``, still applies); ``PROBE_NARROW_CORE=1`` (session 94) the model's beam
under ``colour_correction`` continued into its saturated core as the edge's Gaussian plus a narrower one at the
spot's centre, ``edge * 10**core_narrow_log10_peak * (exp(-r^2 / 2 s^2) - exp(-R^2 / 2 s^2))`` (``s``:
``core_narrow_ref_px``; zero at the edge), two parameters fitted.

The session-94 knobs' outputs (``docs/bench/session94/oracles/``) were made at a5edf90's package: from 220b408 on the
package continues the core with its own narrower beam under ``colour_correction``, on which ``PROBE_NARROW_CORE``
would stack a second one (run those knobs at a5edf90, e.g. with that checkout first on ``PYTHONPATH``).

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
KNOBS = (
    "PROBE_GREY",
    "PROBE_NO_MOSAIC",
    "PROBE_UNSATURATED",
    "PROBE_UNIFORM_METER",
    "PROBE_UNIFORM_LUMA_METER",
    "PROBE_CENTRED_MEAN_METER",
    "PROBE_CORE_UNSCORED",
    "PROBE_CORE_PROFILED",
    "PROBE_NO_BLOOM",
    "PROBE_NARROW_CORE",
)
ON = {knob: os.environ.get(knob) == "1" for knob in KNOBS}
CASE = sim.CASE_BY_NAME["blinding_auto_exposure"]


def meter_form(*, centred: bool, luma: bool):
    """camsim's meter with its centre weighting (``centred``) and its luminance (``luma``; else the channel mean)
    each kept or replaced by the model's form."""

    def meter(irradiance: np.ndarray, cam: cs.Camera) -> float:
        h, w = irradiance.shape[:2]
        yy, xx = np.mgrid[0:h, 0:w].astype(float)
        weight = np.exp(-(((yy - h / 2) / (0.6 * h)) ** 2 + ((xx - w / 2) / (0.6 * w)) ** 2))
        weight /= weight.sum()
        light = irradiance @ cs.LUMA if luma else irradiance.mean(-1)
        low, high = np.log(1e-4), np.log(1e3)
        for _ in range(40):
            mid = (low + high) / 2
            clipped = np.minimum(np.exp(mid) * light, 1.0)
            if ((clipped * weight).sum() if centred else clipped.mean()) < cam.exposure_target:
                low = mid
            else:
                high = mid
        return float(np.exp((low + high) / 2))

    return meter


if ON["PROBE_UNSATURATED"]:
    spot = cs.laser_spot
    cs.laser_spot = lambda cam, centre, colour, *, core_px, halo: spot(
        cam, centre, colour, core_px=core_px, halo=None
    )
    sim.CASE_BY_NAME[CASE.name] = dataclasses.replace(
        CASE, render=lambda rng, cam: cs.laser_blinding_pairs(rng, cam, sim.N_PAIRS, halo=True)
    )
if ON["PROBE_NO_BLOOM"]:
    spot_with_bloom = cs.laser_spot

    def spot_without_bloom(cam, centre, colour, *, core_px, halo):
        # camsim's bloom is 0.15 of the core at 2.5 times its width: the difference of the two spots at a core
        # 2.5 times wider, scaled, is that bloom
        bloomed = spot_with_bloom(cam, centre, colour, core_px=core_px, halo=halo)
        yy, xx = np.mgrid[0 : cam.height, 0 : cam.width].astype(float)
        r2 = (yy - centre[0]) ** 2 + (xx - centre[1]) ** 2
        return bloomed - (0.15 * np.exp(-r2 / (2 * (2.5 * core_px) ** 2)))[..., None] * colour

    cs.laser_spot = spot_without_bloom
if ON["PROBE_NO_MOSAIC"]:
    cs.mosaic = lambda linear: linear.copy()
    cs.demosaic = lambda raw: raw
if ON["PROBE_GREY"]:
    reflectance = cs.scene_reflectance
    cs.scene_reflectance = lambda *a: np.repeat(reflectance(*a).mean(-1, keepdims=True), 3, axis=-1)
if ON["PROBE_UNIFORM_METER"]:
    cs.meter = meter_form(centred=False, luma=False)
if ON["PROBE_UNIFORM_LUMA_METER"]:
    cs.meter = meter_form(centred=False, luma=True)
if ON["PROBE_CENTRED_MEAN_METER"]:
    cs.meter = meter_form(centred=True, luma=False)
if ON["PROBE_CORE_UNSCORED"] or ON["PROBE_CORE_PROFILED"]:
    # the fits' features carry the frame's values, which only a fit's prediction reads
    stacked_pixels, predict_features = (
        model.BlindingFrames.stacked_pixels,
        model.BlindingFrames.predict_features,
    )

    def stacked_with_target(self, items, pixels):
        stacked, target = stacked_pixels(self, items, pixels)
        return {**stacked, "attacked": target}, target

    model.BlindingFrames.stacked_pixels = stacked_with_target
if ON["PROBE_CORE_UNSCORED"]:

    def predict_unscored_core(self, effects, params, f, probes=None):
        prediction = predict_features(self, effects, params, f, probes)
        if "attacked" not in f or "colour_correction" not in effects:
            return prediction
        core = f["core_depth"][:, self.laser_channel] > 0
        fainter = torch.arange(3) != self.laser_channel
        unscored = core.unsqueeze(1) & fainter
        return torch.where(unscored, f["attacked"], prediction)

    model.BlindingFrames.predict_features = predict_unscored_core
if ON["PROBE_CORE_PROFILED"]:
    from lerobot_phantom.transforms import physics
    from lerobot_phantom.transforms.capture import core_continued

    PROFILE_STEPS = 256

    def predict_profiled_core(self, effects, params, f, probes=None):
        prediction = predict_features(self, effects, params, f, probes)
        if "attacked" not in f or "colour_correction" not in effects:
            return prediction
        core = f["core_depth"][:, self.laser_channel] > 0
        if not bool(core.any()):
            return prediction
        decode, encode = self.memoised_tone_curve(effects, params)
        matrix = model.correction_matrix(params)
        per_stored = physics.raw_light_per_stored(matrix, self.raw_laser_colour(params), self.laser_channel)
        channel = slice(self.laser_channel, self.laser_channel + 1)
        beam = core_continued(
            decode(f["beam"])[:, channel],
            decode(f["dark"])[:, channel],
            f["core_depth"][:, channel],
            f["core_radius"][:, channel],
            params["core_sigma_ref_px"],
        )
        scale = f["strength"] * f["exposure"] * model.laser_gain(params)
        total = self.compose(effects, params, f, decode)
        continued = scale * beam
        if "auto_exposure" in effects:
            factor = self.exposure_factor(effects, params, decode, probes)[f["pair"]].unsqueeze(1)
        else:
            factor = torch.ones_like(continued)
        rest, continued, factor = (total - continued * per_stored)[core], continued[core], factor[core]
        grid = torch.logspace(-2, np.log10(3000.0), PROFILE_STEPS, dtype=torch.float64)
        light = torch.cat([grid.expand(len(rest), -1), continued], dim=1)  # (n, steps + 1)
        raw = (factor.unsqueeze(1) * (rest.unsqueeze(1) + light.unsqueeze(2) * per_stored)).clamp(0.0, 1.0)
        stored = (raw @ matrix.T).clamp(0.0, 1.0)  # (n, steps + 1, 3)
        misfit = ((stored - decode(f["attacked"][core]).unsqueeze(1)) ** 2).sum(2)
        best = misfit.argmin(1)
        read = stored[torch.arange(len(best)), best]
        out = prediction.clone()
        out[core] = encode(read)
        return out

    model.BlindingFrames.predict_features = predict_profiled_core
if ON["PROBE_NARROW_CORE"]:
    from lerobot_phantom.transforms import capture as capture_module

    edge_continued = capture_module.core_continued
    specs_without_core = model.BlindingFrames.param_specs
    compose_raw_without_core = model.BlindingFrames.compose_raw
    narrow = {}

    def specs_with_core(self, effects):
        specs = specs_without_core(self, effects)
        if "colour_correction" not in effects:
            return specs
        return [
            *specs,
            core.Param("core_narrow_log10_peak", 1.0, 0.0, 4.0, scale=0.5),
            core.Param("core_narrow_ref_px", 8.0, 1.0, 60.0, scale=3.0),
        ]

    def continued_with_core(pattern, dark, core_depth, core_radius, core_sigma_ref_px):
        beam = edge_continued(pattern, dark, core_depth, core_radius, core_sigma_ref_px)
        if not narrow:
            return beam
        depth = torch.minimum(core_depth, core_radius)
        s2 = 2.0 * narrow["core_narrow_ref_px"] ** 2
        bump = torch.exp(-((core_radius - depth) ** 2) / s2) - torch.exp(-(core_radius**2) / s2)
        edge = (pattern - dark).clamp(min=0.0)
        return beam + torch.where(depth > 0, edge * 10 ** narrow["core_narrow_log10_peak"] * bump, 0.0)

    def compose_raw_with_core(self, effects, params, f, decode):
        narrow.update({k: params[k] for k in ("core_narrow_log10_peak", "core_narrow_ref_px")})
        try:
            return compose_raw_without_core(self, effects, params, f, decode)
        finally:
            narrow.clear()

    model.core_continued = continued_with_core
    model.BlindingFrames.param_specs = specs_with_core
    model.BlindingFrames.compose_raw = compose_raw_with_core
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
