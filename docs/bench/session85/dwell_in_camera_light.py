"""The dwell share read in the camera's own light against the package's read (``BlurFrames.dwell_share``, the tone
curve a shouldered power law fitted with it): per camsim blur case and master seed, the resonance with
``sensor_gamma`` is fitted on the calibration's fit pairs, then the dwell share is refitted with the path, once as
the package reads it and once with every frame decoded and encoded by camsim's own tone curve (``camsim.tone_curve``,
inverted by interpolation on 4097 points), the light the frames were averaged in. Where the two agree, the package's
tone curve is not what sets the share; a share that stays low in the camera's own light is in the frames.

Usage: ``PYTHONPATH=. python docs/bench/session85/dwell_in_camera_light.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session83"))
sys.path.insert(1, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
import camsim
from across_share import each_case_draw

from lerobot_phantom.calibration.frame_models.ultrasound_blur import PATH_PARAMS, fit_dwell_share
from lerobot_phantom.transforms import physics

RESONANCE = frozenset({"sinusoidal_motion", "sensor_gamma"})


def dwell_in_camera_light(problem, fit, items, camera) -> float:
    """The dwell share (0 uniform, 1 arcsine) that best fits ``items`` with the path refitted, every frame in the
    linear light of ``camera``'s tone curve."""
    light = np.linspace(0.0, 1.0, 4097)
    encoded = camsim.tone_curve(light, camera)

    def decode(values: torch.Tensor) -> torch.Tensor:
        return torch.from_numpy(np.interp(values.numpy(), encoded, light))

    def encode(values: torch.Tensor) -> torch.Tensor:
        return torch.from_numpy(camsim.tone_curve(np.clip(values.numpy(), 0.0, 1.0), camera))

    uniform = physics.blur_path_offsets("uniform", problem.taps, dtype=torch.float64)
    arcsine = physics.blur_path_offsets("sinusoidal", problem.taps, dtype=torch.float64)
    clean = {int(i): decode(problem.pairs[int(i)].clean.unsqueeze(0)) for i in items}

    def errors(p):
        offsets = (1 - p["dwell_share"]) * uniform + p["dwell_share"] * arcsine
        parts = []
        for i, linear in clean.items():
            pair = problem.pairs[i]
            scale = pair.intensity / pair.to_reference
            blurred = physics.line_blur(linear, p["dx_ref_px"] * scale, p["dy_ref_px"] * scale, offsets)
            parts.append((encode(blurred)[0] - pair.attacked).ravel())
        return torch.cat(parts)

    # fitted with the path as the package fits it; the tone curve here is camsim's, fixed
    held = {name: fit.params[name] for name in PATH_PARAMS}
    return fit_dwell_share(problem.param_specs(frozenset()), errors, held)


def print_both(label: str, problem, items, camera) -> None:
    fit = problem.fit(RESONANCE, items)
    print(
        f"{label}: package {problem.dwell_share(fit, items):.3f}, "
        f"camera's own curve {dwell_in_camera_light(problem, fit, items, camera):.3f}",
        flush=True,
    )


def main() -> None:
    each_case_draw(print_both, "dwell share: the package's read, and the read in the camera's own light")


if __name__ == "__main__":
    main()
