"""How much the independent simulator's planted laser glare changes the blinded frames (session 12).

Noise-free renders of one scene plus the laser at intensity 0.6, with and without the glare tail, through the
simulator's optics and tone curve; prints the mean absolute change (grey levels) and the share of pixels changed by
more than 3 levels. ``old``: the draw used until session 12 (amplitude 0.5-1.5% of the core, scale 1-2.5 px,
exponent 1.4-2.4), on session 11's case seed and seeds 1-12. ``new``: the draw of ``camsim.laser_blinding_pairs``
(level 0.2-0.8% of the core's peak a quarter of the diagonal out, scale 3-6 px, exponent 1.5-2.2), seeds 0-19.
The draws are replicated here in the same order as the simulator makes them.

    python3 docs/bench/camsim_glare_size.py   (from the repository root)
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "calibration"))
sys.path.insert(
    1, str(Path(__file__).resolve().parents[2] / "tests")
)  # tests/sampling.py, which the case selection imports
import camsim as cs

# the test module reads its master seed on import; only its camera draw is used
os.environ.setdefault("CAMSIM_SEED", "0")
import test_independent_sim as tis


def old_glare(rng, cam):
    return rng.uniform(5e-3, 1.5e-2), rng.uniform(1.0, 2.5), rng.uniform(1.4, 2.4)


def new_glare(rng, cam):
    scale_px, exponent = rng.uniform(3.0, 6.0), rng.uniform(1.5, 2.2)
    at_quarter = np.exp(rng.uniform(np.log(2e-3), np.log(8e-3)))
    quarter = 0.25 * np.hypot(cam.height, cam.width)
    return at_quarter * (1 + (quarter / scale_px) ** 2) ** (exponent / 2), scale_px, exponent


def glare_size(seed: int, draw) -> tuple[float, float]:
    rng = np.random.default_rng(seed)
    cam = tis.random_camera(rng)
    colour = cs.LASER_COLOURS[rng.choice(list(cs.LASER_COLOURS))]
    centre = (rng.uniform(0.3, 0.7) * cam.height, rng.uniform(0.3, 0.7) * cam.width)
    glare = draw(rng, cam)
    core_px, peak = rng.uniform(2.5, 4.0), rng.uniform(40, 120)
    refl, light = cs.scene(np.random.default_rng(seed + 1), cam)
    exposure = cs.meter(cs.optics(refl * light, cam), cam)
    frames = []
    for tail in (glare, None):
        spot = cs.laser_spot(cam, centre, colour, core_px=core_px, halo=tail)
        linear = np.clip(exposure * cs.optics(refl * light + 0.6 * peak * spot, cam), 0, 1)
        frames.append(cs.tone_curve(linear, cam) * 255)
    change = np.abs(frames[0] - frames[1])
    return float(change.mean()), float(np.mean(change > 3))


def main() -> None:
    for name, draw, seeds in (("old", old_glare, [1327245372, *range(1, 13)]), ("new", new_glare, range(20))):
        sizes = np.array([glare_size(s, draw) for s in seeds])
        print(
            f"{name}: {len(sizes)} draws, mean change {sizes[:, 0].min():.2f}-{sizes[:, 0].max():.2f} grey levels "
            f"(median {np.median(sizes[:, 0]):.2f}), share of pixels > 3 levels at most {sizes[:, 1].max():.2f}"
        )


if __name__ == "__main__":
    main()
