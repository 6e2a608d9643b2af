"""The dwell read on the frames' difference low-passed: per camsim blur case and master seed, the resonance
(``sinusoidal_motion``) fitted on the calibration's fit pairs, then the dwell share read as the package reads it
(``BlurFrames.dwell_share``) and again with each pair's residual (the clean frame blurred along the path, minus the
attacked frame; ``BlurFrames.dwell_residuals`` per pair) smoothed by a Gaussian of ``SIGMAS`` pixels of the frame
(``physics.gaussian_spread``, edges repeated; ``DWELL_SIGMAS``: a comma list, default 0.7,1,1.5) before it is
squared: the clean frame carries the camera's demosaic and JPEG error at its finest scale, which the model blurs
along with the scene, while the attacked frame's was made after the blur.

Usage: ``PYTHONPATH=. python docs/bench/session98/dwell_lowpass.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.frame_models.ultrasound_blur import fit_dwell_share
from lerobot_phantom.transforms import physics

MODEL = frozenset({"sinusoidal_motion"})
SIGMAS = tuple(float(v) for v in os.environ.get("DWELL_SIGMAS", "0.7,1,1.5").split(","))


def lowpass_residuals(problem, items, params, sigma: float) -> torch.Tensor:
    share = params["dwell_share"]
    uniform = physics.blur_path_offsets("uniform", problem.taps, dtype=torch.float64)
    arcsine = physics.blur_path_offsets("sinusoidal", problem.taps, dtype=torch.float64)
    offsets = (1 - share) * uniform + share * arcsine
    parts = []
    for i in items:
        pair = problem.pairs[int(i)]
        difference = (
            problem.path_blur(params, int(i), offsets, params["gamma"], shoulder=True) - pair.attacked
        )
        parts.append(physics.gaussian_spread(difference[None], sigma)[0].ravel())
    return torch.cat(parts)


def main() -> None:
    cases, seeds = sys.argv[1].split(","), [int(s) for s in sys.argv[2:]]
    for name in cases:
        for master, sim, _case, case_seed, _rng, camera in case_draws(name, seeds):
            with tempfile.TemporaryDirectory() as folder:
                problem, items = sim.drawn_problem(name, case_seed, Path(folder))
                fit = problem.fit(MODEL, items)
                reads = [f"as read {problem.dwell_share(fit, items):.3f}"]
                for sigma in SIGMAS:
                    share = fit_dwell_share(
                        problem.dwell_specs(),
                        lambda p, s=sigma, pr=problem, it=items: lowpass_residuals(pr, it, p, s),
                        problem.dwell_start(fit),
                    )
                    reads.append(f"low-passed {sigma:g} px {share:.3f}")
            print(f"{name} master {master} ({camera.tone}): dwell share {'; '.join(reads)}", flush=True)


if __name__ == "__main__":
    main()
