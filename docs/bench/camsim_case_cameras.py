"""The camera each camsim case draws on given master seeds, exactly as the test draws it (nothing is rendered).

Usage: ``PYTHONPATH=. python docs/bench/camsim_case_cameras.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "calibration"))
sys.path.insert(
    1, str(Path(__file__).resolve().parents[2] / "tests")
)  # tests/sampling.py, which the case selection imports


def case_draws(name: str, seeds) -> Iterator[tuple[int, object, object, int, np.random.Generator, object]]:
    """(master seed, the test module for it, case, case seed, generator, camera) per master seed, as the test
    draws them: the generator is where the camera's draws left it, so ``case.render(rng, camera)`` renders the
    case's pairs."""
    for master in seeds:
        os.environ["CAMSIM_SEED"] = str(master)
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        case = sim.CASE_BY_NAME[name]
        yield (master, sim, case, *sim.case_camera(case))


def main() -> None:
    cases, seeds = sys.argv[1].split(","), [int(s) for s in sys.argv[2:]]
    for name in cases:
        for master, _sim, _case, _seed, _rng, camera in case_draws(name, seeds):
            gamma = f" {camera.tone_gamma:.2f}" if camera.tone == "power" else ""
            print(
                f"master {master} {name}: tone {camera.tone}{gamma}, full well {camera.full_well_e:.0f} e, "
                f"PSF core sigma {camera.psf_sigma_px:.2f} px"
            )


if __name__ == "__main__":
    main()
