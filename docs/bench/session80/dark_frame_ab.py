"""A dark frame's worth on camsim's glare case: each master seed's ``blinding_halo`` draw calibrated as the test
renders it (arm ``plain``) and with the laser capture's dark frame added (camsim's ``dark_frame``: every other draw
the same, checked here), into ``OUTDIR/bt_SEED/ARM/``. The dark frame is read two ways:

- ``shape``: as the package reads it (``laser_blinding.dark_field``: the room's shape, a quadratic surface fitted to
  the dark frame, taken out of the capture, whose dark level is then read as without a dark frame, and put back;
  the halo adds back the glare that level holds);
- ``whole``: the quadratic surface subtracted whole, and no glare added back (a dark frame holds none): it replaces
  ``dark_field`` and puts ``dark_level_radius`` at 1e30 px (the halo there is at most 1e-6 of its amplitude, its
  exponent's lowest bound being 0.2). Prints per arm the named causes, the test's verdict, the
extended model's held-out RMSE, the cross-validated scores of linear light alone and with the glare (the selection's
first step: the room's gradient read as laser light shows in the first) and the glare's fitted level and exponent beside the planted exponent.

Usage: ``PYTHONPATH=. python docs/bench/session80/dark_frame_ab.py OUTDIR [--arms plain,shape,whole]
SEED...``
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.frame_models import laser_blinding
from lerobot_phantom.transforms import physics

CASE = "blinding_halo"
PACKAGE = (laser_blinding.dark_field, laser_blinding.dark_level_radius)


def whole_surface(pair, centre):
    return physics.linear_to_srgb(laser_blinding.dark_surface(pair.pattern_dark).clamp(min=0.0))


READINGS = {
    "plain": PACKAGE,
    "shape": PACKAGE,
    "whole": (whole_surface, lambda pattern, centre: 1e30),
}


def render_with_dark_frame(camsim, rng: np.random.Generator, camera, n_pairs: int) -> tuple[list, float]:
    """The draw with a dark frame, and the glare exponent it plants (read from camsim's spot as it is drawn)."""
    spot, seen = camsim.laser_spot, {}

    def recording_spot(cam, centre, colour, **options):
        seen["exponent"] = options["halo"][2]
        return spot(cam, centre, colour, **options)

    camsim.laser_spot = recording_spot
    try:
        pairs = camsim.laser_blinding_pairs(rng, camera, n_pairs, halo=True, dark_frame=True)
    finally:
        camsim.laser_spot = spot
    return pairs, seen["exponent"]


def glare_beside_linear_light(steps: list[dict]) -> str:
    """The selection's first step: the cross-validated score of linear light alone, and with the glare (and the
    glare's share under it) where that pair was scored."""
    tried = steps[0]["tried"]
    linear, with_glare = tried["linear_light_saturation"], tried.get("linear_light_saturation+halo_power_law")
    if with_glare is None:
        return f"CV linear light {linear:.3f}, with the glare not scored"
    return f"CV linear light {linear:.3f}, with the glare {with_glare:.3f} ({100 * (1 - with_glare / linear):+.1f}%)"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("out", type=Path)
    parser.add_argument("seeds", type=int, nargs="+")
    parser.add_argument("--arms", default="plain,shape")
    args = parser.parse_args()
    arms = args.arms.split(",")
    unknown = sorted(set(arms) - set(READINGS))
    if unknown:
        raise SystemExit(f"unknown arms {unknown}; valid: {sorted(READINGS)}")
    for master, sim, case, seed, rng, camera in case_draws(CASE, args.seeds):
        import camsim

        plain = case.render(copy.deepcopy(rng), camera)
        dark, exponent = render_with_dark_frame(camsim, copy.deepcopy(rng), camera, sim.N_PAIRS)
        same = all(
            np.array_equal(a.clean, b.clean)
            and np.array_equal(a.attacked, b.attacked)
            and np.array_equal(a.pattern, b.pattern)
            and a.intensity == b.intensity
            for a, b in zip(plain, dark, strict=True)
        )
        if not same or plain[0].pattern_dark is not None or dark[0].pattern_dark is None:
            raise SystemExit(f"{master}: the dark frame changed another draw of the case")
        for arm in arms:
            folder = args.out / f"bt_{master}" / arm
            folder.mkdir(parents=True)
            camsim.write_pairs(folder / "pairs", plain if arm == "plain" else dark)
            laser_blinding.dark_field, laser_blinding.dark_level_radius = READINGS[arm]
            began = time.perf_counter()
            report = calibrate(
                CalibrateConfig(
                    attack=case.attack,
                    measured=str(folder / "pairs"),
                    out=str(folder / "out"),
                    seed=seed % 2**31,
                )
            )
            params = report["extended"]["params"]
            glare = (
                f"level {params['halo_level']:.3f} exponent {params['halo_exponent']:.2f}"
                if "halo_level" in params
                else "no glare"
            )
            print(
                f"{master} {arm}: named {sorted(sim.named_causes(report))} "
                f"{'pass' if sim.passes(case, report, camera) else 'MISS'}; held-out RMSE base "
                f"{report['base']['heldout_rmse']:.3f} extended {report['extended']['heldout_rmse']:.3f}; "
                f"{glare_beside_linear_light(report['selection']['steps'])}; {glare} (planted exponent {exponent:.2f}); {time.perf_counter() - began:.0f} s",
                flush=True,
            )


if __name__ == "__main__":
    main()
