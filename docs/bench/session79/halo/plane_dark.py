"""camsim ``blinding_halo`` with the capture's dark level read as a plane: in the laser's channel, a plane fitted to
the capture's outer half (linear light, sRGB; least squares, then again without values over 2.5 robust deviations
from it), and the dark level per pixel is the package's median plus the plane's departure from its own median over
the farthest tenth (in the other channels times the laser's colour, as ``oracle_dark.py`` adds the true room's).
The glare in the outer half is read into the plane too: this is the reading a capture alone allows.

Usage: ``PYTHONPATH=. python docs/bench/session79/halo/plane_dark.py CASE_DIR...`` (sRGB cameras)"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
from addback_survey import survey

from lerobot_phantom.calibration.frame_models import laser_blinding
from lerobot_phantom.transforms import physics

ROBUST_DEVIATIONS = 2.5


def plane_departure(pattern: torch.Tensor, centre: tuple[float, float], channel: int) -> torch.Tensor:
    """(H*W,) the fitted plane's departure from its median over the capture's farthest tenth, linear light."""
    _, height, width = pattern.shape
    ys, xs = np.mgrid[0:height, 0:width]
    radius, far = laser_blinding.dark_region(pattern, centre)
    outer = (radius >= radius.median()).numpy()
    values = physics.srgb_to_linear(pattern[channel]).numpy().ravel()
    design = np.stack([np.ones(height * width), xs.ravel(), ys.ravel()], axis=1)
    keep = outer.copy()
    for _ in range(2):
        coef, *_ = np.linalg.lstsq(design[keep], values[keep], rcond=None)
        residual = values - design @ coef
        spread = 1.4826 * np.median(np.abs(residual[outer] - np.median(residual[outer])))
        keep = outer & (np.abs(residual) <= ROBUST_DEVIATIONS * spread)
    plane = design @ coef
    return torch.from_numpy(plane - np.median(plane[far.numpy()]))


def main() -> None:
    features = laser_blinding.BlindingFrames.features

    def plane_features(self, index, pixels):
        f = features(self, index, pixels)
        if not hasattr(self, "plane_departures"):
            self.plane_departures = {}
        if index not in self.plane_departures:
            pattern = self.pairs[index].pattern
            self.plane_departures[index] = plane_departure(pattern, self.centres[index], self.laser_channel)
        rows = self.plane_departures[index].reshape(-1, 1)
        rows = rows if pixels is None else rows[pixels]
        f["dark"] = physics.linear_to_srgb(
            physics.srgb_to_linear(f["dark"]) + rows * self.colours[index].reshape(1, 3)
        )
        return f

    laser_blinding.BlindingFrames.features = plane_features
    for case in sys.argv[1:]:
        print(f"plane dark level: {survey(Path(case))}", flush=True)


if __name__ == "__main__":
    main()
