"""How well a laser capture alone gives its dark room's gradient, against the dark frame's surface (session 96).

For camsim blinding_halo draws written with their dark frames (``halo_with_dark_frame.py``), each draw's capture (one
per session) is read four ways and compared, in the laser's channel, with the dark frame's quadratic surface
(``capture.dark_surface``), both taken about their median over the capture's farthest tenth: one level (no
gradient), the per-channel unweighted odd-part fit of c9117c2 (written out here), the same weighed against each
channel's light, and the package's ``capture.room_gradient`` (one relative slope for all channels, weighed). Prints
the largest absolute error, linear light x 1e3.

    PYTHONPATH=. python docs/bench/session96/room_gradient_variants.py PAIRS_DIR...
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch
from PIL import Image

from lerobot_phantom.transforms import capture as C


def load(path: Path) -> torch.Tensor:
    return torch.tensor(np.asarray(Image.open(path)), dtype=torch.float64).permute(2, 0, 1) / 255


def per_channel(capture: torch.Tensor, centre: tuple[float, float], weighed: bool) -> torch.Tensor:
    light, mirrored, dx, dy, use = C.mirrored_pairs(capture, centre)
    even = 0.5 * (light + mirrored)
    grad_y, grad_x = torch.gradient(even, dim=(1, 2))
    _, far = C.dark_region(capture, centre)
    level = C.far_median(light, far)
    slopes = []
    for c in range(3):
        terms = torch.stack([dx[use], dy[use], grad_x[c][use], grad_y[c][use]], dim=1)
        odd = 0.5 * (light[c] - mirrored[c])[use]
        if weighed:
            weight = 1.0 / ((even[c][use] - level[c, 0, 0]).clamp(min=0.0) + level[c, 0, 0] + C.DARKEST_LIGHT)
            terms, odd = terms * weight[:, None], odd * weight
        slopes.append(torch.linalg.lstsq(terms, odd[:, None]).solution[:2, 0])
    g = torch.stack(slopes, dim=1)
    return g[0].reshape(3, 1, 1) * dx + g[1].reshape(3, 1, 1) * dy


def main() -> None:
    readings = {
        "one level": lambda capture, centre: torch.zeros_like(capture),
        "per channel (c9117c2)": lambda capture, centre: per_channel(capture, centre, weighed=False),
        "per channel, weighed": lambda capture, centre: per_channel(capture, centre, weighed=True),
        "one relative slope, weighed (package)": C.room_gradient,
    }
    folders = [Path(p) for p in sys.argv[1:]]
    print("draw (pairs folder's parent): " + ", ".join(f.parent.name for f in folders))
    for name, read in readings.items():
        errors = []
        for folder in folders:
            capture, dark = load(folder / "pattern_000.png"), load(folder / "pattern_dark_000.png")
            centre = C.pattern_centre(capture)
            _, far = C.dark_region(capture, centre)
            surface = C.dark_surface(dark)
            truth = surface - C.far_median(surface, far)
            estimate = read(capture, centre)
            estimate = estimate - C.far_median(estimate, far)
            laser = int(C.capture_colour(capture).argmax())
            errors.append(float((truth - estimate)[laser].abs().max()) * 1e3)
        print(f"{name:40s} " + "  ".join(f"{e:5.2f}" for e in errors))


if __name__ == "__main__":
    main()
