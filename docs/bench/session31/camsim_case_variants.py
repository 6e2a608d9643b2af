"""One camsim core case, rendered and calibrated as ``tests/calibration/test_independent_sim.py`` does for a master
seed, as tested or in one of six variants (sessions 31 and 32; no variant is in the package or the test):

- ``as_tested``: the case itself;
- ``no_psf``: the camera's optics blur switched off (core sigma 0.05 px, no wide part) after the camera's draws, so
  every other draw is the same: do the planted effects get named when the emitted pattern's edges stay sharp?
- ``projector_gamma``: light projection is also offered a projector transfer term (a prototype): the pattern is
  the frame the projector was sent, its light that frame through the projector's own display gamma
  (``projector_gamma``, 1-3.5) instead of through the camera's tone curve.
- ``library_curve`` (session 32): camsim's filmic curve (ACES on a 4x pre-gain, then sRGB) replaced by the library's
  own shoulder form at its closest fit to it (shoulder 38.8, knee exponent 1.19, no display gamma: 0.48 grey levels
  RMS, ``camsim_session15/filmic_shoulder_fit.txt``): is reflectance named when the camera's curve is in the
  library's family?
- ``pattern_gamma`` (session 32): models that compose linear light (``sensor_gamma`` or ``tone_shoulder``) take an
  emitted pattern's light as the frame through camsim's projector gamma (``frame ** 2.2``) instead of decoding it
  through the fitted camera curve.
- ``pattern_gamma_4`` (session 32): ``pattern_gamma`` with light projection selection scoring groups of up to four
  new effects (``joint_effects = 4``), so additive light + shoulder + cross-talk + reflectance can be scored at once.
- ``groups_4`` (session 32): the case as tested, but light projection selection scores groups of up to four.

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/session31/camsim_case_variants.py CASE MASTER_SEED ROOT MODE``
from the repository root (``CAMSIM_SEED`` only has to exist for the import; MASTER_SEED replaces it). Prints the
named causes (the test's rule), the planted ones missing, the camera's tone curve, the held-out RMSE of the base and
of the written model and this process's CPU seconds.
"""

from __future__ import annotations

import dataclasses
import importlib
import os
import sys
import time

import numpy as np
import torch

from lerobot_phantom.calibration import projection
from lerobot_phantom.calibration.core import Effect, Param
from lerobot_phantom.calibration.frame_models import light_projection
from lerobot_phantom.calibration.tone import shoulder_encode

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports

MODES = (
    "as_tested",
    "no_psf",
    "projector_gamma",
    "library_curve",
    "pattern_gamma",
    "pattern_gamma_4",
    "groups_4",
)
CAMSIM_PROJECTOR_GAMMA = 2.2
LINEAR_LIGHT_FORMS = frozenset({"sensor_gamma", "tone_shoulder"})
CLOSEST_SHOULDER = {"shoulder": 38.8, "shoulder_exponent": 1.19}
PROJECTOR_GAMMA = Effect(
    "projector_gamma",
    "the pattern is the frame the projector was sent: its light is that frame through the projector's own display "
    "gamma, not the camera's tone curve",
    requires=("additive_light",),
)


def offer_projector_gamma() -> None:
    library_specs, library_predict = projection.projection_specs, projection.projection_predict

    def specs(effects):
        found = library_specs(effects)
        if "projector_gamma" in effects:
            found.append(Param("projector_gamma", 2.2, 1.0, 3.5, scale=0.5))
        return found

    def predict(surface, projected, strength, effects, params):
        if "projector_gamma" not in effects:
            return library_predict(surface, projected, strength, effects, params)
        # the library decodes the pattern through the camera's curve: hand it the projector's light encoded by it
        _, encode = projection.tone_curve(effects, params)
        return library_predict(
            surface,
            encode(projected.clamp(min=1e-12) ** params["projector_gamma"]),
            strength,
            effects,
            params,
        )

    light_projection.ProjectionFrames.candidates = (*projection.EFFECTS, PROJECTOR_GAMMA)
    projection.projection_specs = specs
    projection.projection_predict = predict
    light_projection.projection_predict = predict


def use_library_curve() -> None:
    camsim = importlib.import_module("camsim")
    camsim_curve = camsim.tone_curve

    def library_family(linear, cam):
        if cam.tone != "filmic":
            return camsim_curve(linear, cam)
        linear = torch.from_numpy(np.clip(linear, 0.0, 1.0).astype(np.float64))
        return shoulder_encode(linear, CLOSEST_SHOULDER).numpy()

    camsim.tone_curve = library_family


def decode_pattern_by_projector_gamma() -> None:
    frames = light_projection.ProjectionFrames
    library_curve, library_predict = projection.tone_curve, frames.predict_features

    def projector_light(pattern):
        return pattern.clamp(min=0.0) ** CAMSIM_PROJECTOR_GAMMA

    def pattern_curve(effects, params):  # what the spread path decodes the whole pattern with
        decode, encode = library_curve(effects, params)
        return (projector_light if LINEAR_LIGHT_FORMS & effects else decode), encode

    def predict(self, effects, params, feats):
        if "light_spread" in effects or not LINEAR_LIGHT_FORMS & effects:
            return library_predict(self, effects, params, feats)
        return projection.projection_predict(
            feats["surface"],
            feats["projected"],
            feats["strength"],
            effects,
            params,
            projected_light=projector_light(feats["projected"]),
        )

    light_projection.tone_curve = pattern_curve
    frames.predict_features = predict


def main(name: str, seed: str, root: str, mode: str) -> None:
    if mode not in MODES:
        raise SystemExit(f"mode {mode!r}: valid modes are {', '.join(MODES)}")
    os.environ["CAMSIM_SEED"] = seed
    if mode == "projector_gamma":
        offer_projector_gamma()
    if mode == "library_curve":
        use_library_curve()
    if mode in ("pattern_gamma", "pattern_gamma_4"):
        decode_pattern_by_projector_gamma()
    if mode in ("pattern_gamma_4", "groups_4"):
        light_projection.ProjectionFrames.joint_effects = 4
    sim = importlib.import_module("test_independent_sim")
    if mode == "no_psf":
        drawn_camera = sim.random_camera

        def sharp_camera(rng, **overrides):
            camera = drawn_camera(rng, **overrides)
            return dataclasses.replace(camera, psf_sigma_px=0.05, psf_wide_share=0.0)

        sim.random_camera = sharp_camera
    started = time.process_time()
    result = sim.run_case(name, root)
    report, named = result["report"], sim.named_causes(result["report"])
    fitted = {k: round(v, 3) for item in report["identification"] for k, v in item["params"].items()}
    print(
        f"{name} {seed} {mode} named {sorted(named)} missing {sorted(sim.CASE_BY_NAME[name].planted - named)} "
        f"tone {result['camera'].tone} heldout {report['base']['heldout_rmse']:.3f} -> "
        f"{report['extended']['heldout_rmse']:.3f} cpu {time.process_time() - started:.0f} s identified {fitted}",
        flush=True,
    )


if __name__ == "__main__":
    main(*sys.argv[1:])
