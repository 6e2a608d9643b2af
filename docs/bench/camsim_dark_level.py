"""Where a laser capture's dark level should be read: the dark room's true light at the spot against estimates
from the capture, on camsim's laser blinding cases.

Usage: ``PYTHONPATH=. python docs/bench/camsim_dark_level.py CASE SEED...`` from the repository root (``SEED``: master
seeds). Renders the case as ``tests/calibration/test_independent_sim.py`` does, records the dark room's light the
simulator drew (its first ``ambient_light`` call, times 0.01, through the optics at the capture's exposure) and
prints, in the laser's channel, its value at the spot against the capture's median over its outer half (the dark
level until session 24), over its farthest tenth (from session 24), and planes fitted to its farthest half and
quarter, evaluated at the spot. All in sRGB-decoded light: comparable to the truth on sRGB cameras only.
"""

from __future__ import annotations

import sys

import numpy as np
import torch

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports
sys.path.insert(0, "tests")

import camsim as cs
from camsim_case_batch import cases_per_master_seed

from lerobot_phantom.calibration.frame_models import laser_blinding as lb
from lerobot_phantom.transforms import physics


def recorded_render(case, rng, cam):
    """Render the case, recording the captures' (irradiance, exposure), the spots and the ambient light drawn."""
    calls, spots, ambient = [], [], []
    capture, laser_spot, ambient_light = cs.capture, cs.laser_spot, cs.ambient_light

    def recording_capture(irradiance, cam_, rng_, exposure=None, **kwargs):
        calls.append((irradiance, exposure))
        return capture(irradiance, cam_, rng_, exposure=exposure, **kwargs)

    def recording_spot(cam_, centre, colour, *, core_px, halo):
        spot = laser_spot(cam_, centre, colour, core_px=core_px, halo=halo)
        spots.append((centre, spot))
        return spot

    def recording_ambient(rng_, height, width):
        ambient.append(ambient_light(rng_, height, width))
        return ambient[-1]

    cs.capture, cs.laser_spot, cs.ambient_light = recording_capture, recording_spot, recording_ambient
    try:
        pairs = case.render(rng, cam)
    finally:
        cs.capture, cs.laser_spot, cs.ambient_light = capture, laser_spot, ambient_light
    return pairs, calls, spots, ambient


def capture_estimates(linear: np.ndarray, centre: tuple[float, float]) -> tuple[float, float, float, float]:
    """Dark-level estimates from one channel of a capture (linear): medians over its outer half and farthest tenth
    by distance from the spot, and planes fitted to its farthest half and quarter, evaluated at the spot."""
    cx, cy = centre
    yy, xx = np.mgrid[0 : linear.shape[0], 0 : linear.shape[1]].astype(float)
    radius = np.hypot(xx - cx, yy - cy)

    def plane_at_spot(mask):
        design = np.c_[np.ones(mask.sum()), xx[mask], yy[mask]]
        coef, *_ = np.linalg.lstsq(design, linear[mask], rcond=None)
        return float(coef[0] + coef[1] * cx + coef[2] * cy)

    half, tenth, quarter = (radius >= np.quantile(radius, 1 - share) for share in (0.5, 0.1, 0.25))
    return (
        float(np.median(linear[half])),
        float(np.median(linear[tenth])),
        plane_at_spot(half),
        plane_at_spot(quarter),
    )


def main() -> None:
    for seed, sim, case in cases_per_master_seed(sys.argv[1], sys.argv[2:]):
        _, rng, cam = sim.case_camera(case)
        pairs, calls, spots, ambient = recorded_render(case, rng, cam)
        # the laser pattern is the session's second capture (after the first clean frame); the dark room's light
        # is the case's first ambient draw (laser_blinding_pairs: dark = 0.01 * ambient_light)
        _, exposure = calls[1]
        centre, spot = spots[0]
        channel = int(np.argmax(spot.reshape(-1, 3).sum(0)))
        dark_room = cs.optics(0.01 * ambient[0], cam)[..., channel] * exposure
        truth = dark_room[round(centre[0]), round(centre[1])]
        pattern = torch.from_numpy(pairs[0].pattern.astype(np.float64) / 255).permute(2, 0, 1).contiguous()
        estimates = capture_estimates(
            physics.srgb_to_linear(pattern)[channel].numpy(), lb.pattern_centre(pattern)
        )
        print(
            f"{seed} {cam.tone:7s} dark room at the spot {truth:.5f} (frame {dark_room.min():.5f}-"
            f"{dark_room.max():.5f}) | outer-half median {estimates[0]:.5f}, farthest-tenth median "
            f"{estimates[1]:.5f}, plane over the farthest half {estimates[2]:.5f}, quarter {estimates[3]:.5f}"
        )


if __name__ == "__main__":
    main()
