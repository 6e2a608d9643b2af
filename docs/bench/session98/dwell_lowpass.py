"""The dwell read pixel by pixel and over a few smoothing scales: per camsim blur case and master seed, the
resonance (``sinusoidal_motion``) fitted on the calibration's fit pairs, then ``BlurFrames.dwell_share`` with
``DWELL_LOWPASS_PX`` set to 0 (``as read``: each pair's residual compared pixel by pixel, the package's read before
d53b9b7) and to each of ``DWELL_SIGMAS`` (a comma list of pixels of the frame, default 0.7,1,1.5; 1 is the
package's since d53b9b7): the clean frame carries the camera's demosaic and JPEG error at its finest scale, which
the model blurs along with the scene, while the attacked frame's was made after the blur.

Usage: ``[DWELL_SIGMAS=...] PYTHONPATH=. python docs/bench/session98/dwell_lowpass.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.frame_models import ultrasound_blur

MODEL = frozenset({"sinusoidal_motion"})
SIGMAS = tuple(float(v) for v in os.environ.get("DWELL_SIGMAS", "0.7,1,1.5").split(","))


def dwell_over(problem, fit, items, sigma: float) -> float:
    """``problem.dwell_share`` with the residual smoothed over ``sigma`` pixels (0: pixel by pixel)."""
    package = ultrasound_blur.DWELL_LOWPASS_PX
    ultrasound_blur.DWELL_LOWPASS_PX = sigma
    try:
        return problem.dwell_share(fit, items)
    finally:
        ultrasound_blur.DWELL_LOWPASS_PX = package


def main() -> None:
    cases, seeds = sys.argv[1].split(","), [int(s) for s in sys.argv[2:]]
    for name in cases:
        for master, sim, _case, case_seed, _rng, camera in case_draws(name, seeds):
            with tempfile.TemporaryDirectory() as folder:
                problem, items = sim.drawn_problem(name, case_seed, Path(folder))
                fit = problem.fit(MODEL, items)
                reads = [f"as read {dwell_over(problem, fit, items, 0.0):.3f}"]
                reads += [f"low-passed {s:g} px {dwell_over(problem, fit, items, s):.3f}" for s in SIGMAS]
            print(f"{name} master {master} ({camera.tone}): dwell share {'; '.join(reads)}", flush=True)


if __name__ == "__main__":
    main()
