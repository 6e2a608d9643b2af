"""Which step of camsim's camera pulls the dwell read from the arcsine toward a uniform sweep: per camsim blur case
and master seed, the case rendered as the test renders it, then again with the same random draws but one or more of
the camera's steps taken out of every frame: ``noise`` (the sensor draws its shot and read noise as before, so every
later draw is the test's, and records the expected electrons), ``bayer`` (every pixel records all three channels:
no mosaic, no demosaic) and ``jpeg`` (8-bit quantisation without the JPEG round trip). On each, the resonance
(``sinusoidal_motion``) is fitted on the calibration's fit pairs and the dwell share read
(``BlurFrames.dwell_share``), with the fit's RMSE (grey levels).

Usage: ``PYTHONPATH=. python docs/bench/session98/dwell_pipeline.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import contextlib
import io
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

MODEL = frozenset({"sinusoidal_motion"})
VARIANTS = ((), ("noise",), ("bayer",), ("jpeg",), ("noise", "bayer", "jpeg"))


@contextlib.contextmanager
def without(camsim, steps: tuple[str, ...]):
    """camsim with ``steps`` taken out of its camera (the random draws unchanged)."""
    saved = {name: getattr(camsim, name) for name in ("sensor", "mosaic", "demosaic", "encode")}

    def quiet_sensor(irradiance, exposure, cam, rng, *, extra_exposure=None):
        saved["sensor"](
            irradiance, exposure, cam, rng, extra_exposure=extra_exposure
        )  # the draws of the test
        signal = exposure * irradiance if extra_exposure is None else exposure * irradiance + extra_exposure
        electrons = np.clip(camsim.mosaic(signal) * cam.full_well_e, 0, 50 * cam.full_well_e)
        levels = 2**cam.adc_bits - 1
        code = np.clip(electrons / cam.full_well_e, 0.0, 1.0) * cam.well_share_of_adc
        return np.round(code * levels) / levels

    def plain_encode(image01, cam):
        img = Image.fromarray(np.round(np.clip(image01, 0, 1) * 255).astype(np.uint8))
        buffer = io.BytesIO()
        img.save(buffer, format="PNG")
        return np.asarray(Image.open(io.BytesIO(buffer.getvalue())).convert("RGB")).copy()

    if "noise" in steps:
        camsim.sensor = quiet_sensor
    if "bayer" in steps:
        camsim.mosaic = lambda linear: linear
        camsim.demosaic = lambda raw: raw
    if "jpeg" in steps:
        camsim.encode = plain_encode
    try:
        yield
    finally:
        for name, value in saved.items():
            setattr(camsim, name, value)


def main() -> None:
    cases, seeds = sys.argv[1].split(","), [int(s) for s in sys.argv[2:]]
    for name in cases:
        for master, sim, _case, case_seed, _rng, camera in case_draws(name, seeds):
            reads = []
            for steps in VARIANTS:
                with without(sim.cs, steps), tempfile.TemporaryDirectory() as folder:
                    problem, items = sim.drawn_problem(name, case_seed, Path(folder))
                    fit = problem.fit(MODEL, items)
                    label = "as drawn" if not steps else "no " + "/".join(steps)
                    reads.append(
                        f"{label} {problem.dwell_share(fit, items):.3f} ({problem.rmse(fit, items):.2f})"
                    )
            print(
                f"{name} master {master} ({camera.tone}): dwell share (RMSE) {'; '.join(reads)}", flush=True
            )


if __name__ == "__main__":
    main()
