"""camsim ``blinding_halo``: the laser capture's dark-room light (noise-free, linear, at the capture's exposure) by
distance from the spot, less its median over the capture's farthest tenth (what the package subtracts as the dark
level), times a given gain (the fits' in ``addback_survey.txt``): the light a uniform dark level leaves in the
capture's beam, as the frames see it (full wells per unit intensity); and the planted glare's exponent. Draws
exactly as ``test_independent_sim``.

Usage: ``PYTHONPATH=. python docs/bench/session79/halo/dark_room_gradient.py SEED:LOG10_GAIN...``"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[4] / "tests" / "calibration"))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import camsim
from camsim_case_cameras import case_draws

EDGES = (0, 32, 64, 96, 128, 160, 192, 256)  # reference pixels (the frame's longer side is 256)


def recorded_render(case, rng, camera) -> dict:
    """Render the case, keeping the spot's centre and glare, the dark room's ambient field and the capture's exposure."""
    seen: dict = {}
    spot, ambient, capture = camsim.laser_spot, camsim.ambient_light, camsim.capture

    def recording_spot(cam, centre, colour, **options):
        seen["centre"], seen["glare"] = centre, options["halo"]
        return spot(cam, centre, colour, **options)

    def recording_ambient(rng, height, width):
        field = ambient(rng, height, width)
        seen.setdefault("dark_ambient", field)  # the first call after the spot is the dark room's
        return field

    def recording_capture(irradiance, cam, rng, exposure=None):
        seen.setdefault("capture_exposure", exposure)
        return capture(irradiance, cam, rng, exposure=exposure)

    camsim.laser_spot, camsim.ambient_light, camsim.capture = (
        recording_spot,
        recording_ambient,
        recording_capture,
    )
    try:
        case.render(rng, camera)
    finally:
        camsim.laser_spot, camsim.ambient_light, camsim.capture = spot, ambient, capture
    return seen


def main() -> None:
    for arg in sys.argv[1:]:
        master, log10_gain = int(arg.split(":")[0]), float(arg.split(":")[1])
        for _master, _sim, case, _seed, rng, cam in case_draws("blinding_halo", [master]):
            seen = recorded_render(case, rng, cam)
            dark = camsim.optics(0.01 * seen["dark_ambient"], cam) * seen["capture_exposure"]
            yy, xx = np.mgrid[0 : cam.height, 0 : cam.width]
            radius = (
                np.hypot(yy - seen["centre"][0], xx - seen["centre"][1]) * 256 / max(cam.height, cam.width)
            )
            far = radius >= np.quantile(radius, 0.9)
            level = np.median(dark[far], axis=0)
            left = [
                f"{lo}-{hi}: {10**log10_gain * (dark[(radius >= lo) & (radius < hi)] - level).mean():+.4f}"
                for lo, hi in itertools.pairwise(EDGES)
                if ((radius >= lo) & (radius < hi)).any()
            ]
            exponent = seen["glare"][2]
            print(
                f"{master} (tone {cam.tone}, planted glare exponent {exponent:.2f}, log10 gain {log10_gain}): "
                + ", ".join(left)
            )


if __name__ == "__main__":
    main()
