"""One camsim core case, rendered and calibrated as ``tests/calibration/test_independent_sim.py`` does for a master
seed, as tested or in one of two variants (session 31's diagnosis; neither variant is in the package or the test):

- ``as_tested``: the case itself;
- ``no_psf``: the camera's optics blur switched off (core sigma 0.05 px, no wide part) after the camera's draws, so
  every other draw is the same: do the planted effects get named when the emitted pattern's edges stay sharp?
- ``projector_gamma``: light projection is also offered a projector transfer term (a prototype): the pattern is
  the frame the projector was sent, its light that frame through the projector's own display gamma
  (``projector_gamma``, 1-3.5) instead of through the camera's tone curve.

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

from lerobot_phantom.calibration import projection
from lerobot_phantom.calibration.core import Effect, Param
from lerobot_phantom.calibration.frame_models import light_projection

sys.path.insert(0, "tests/calibration")

MODES = ("as_tested", "no_psf", "projector_gamma")
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


def main(name: str, seed: str, root: str, mode: str) -> None:
    if mode not in MODES:
        raise SystemExit(f"mode {mode!r}: valid modes are {', '.join(MODES)}")
    os.environ["CAMSIM_SEED"] = seed
    if mode == "projector_gamma":
        offer_projector_gamma()
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
