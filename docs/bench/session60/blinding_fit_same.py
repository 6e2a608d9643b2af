"""Laser blinding frame fits on camsim frames, printed as JSON: run at two commits and compare the outputs byte for
byte (session 60: ``PixelProblem.fit`` now calls ``fit_on_pixels`` with the seeded sample; the same fits are expected).

    PYTHONPATH=. python docs/bench/session60/blinding_fit_same.py > OUT.json   (from a checkout's root)
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault(
    "CAMSIM_SEED", "1"
)  # read when the test module is imported; the cases' seeds are given below
sys.path[:0] = [str(Path.cwd() / "tests" / "calibration"), str(Path.cwd() / "tests")]

CASES = (
    ("blinding_saturation", 11, {"linear_light_saturation"}),
    ("blinding_halo", 12, {"halo_power_law", "linear_light_saturation"}),
    ("blinding_null", 13, set()),
)


def main() -> None:
    import camsim as cs
    import test_independent_sim as sim

    from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
    from lerobot_phantom.calibration.core import seeded_split

    fitted = {}
    for name, seed, effects in CASES:
        folder = tempfile.mkdtemp()
        case = sim.CASE_BY_NAME[name]
        _, rng, camera = sim.case_camera(case, seed)
        cs.write_pairs(folder, case.render(rng, camera))
        cfg = CalibrateConfig(attack=case.attack, measured=folder, out=f"{folder}/out", seed=seed)
        problem = build_problem(cfg)
        items, _ = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
        fitted[name] = problem.fit(frozenset(effects), items).params
    print(json.dumps(fitted, sort_keys=True))


if __name__ == "__main__":
    main()
