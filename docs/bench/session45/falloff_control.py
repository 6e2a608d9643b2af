"""camsim's projection falloff case on one master seed, rendered twice from the same draws: as the test renders it,
and with the falloff set to 0 (then it is the digital-overlay null with this case's camera and scenes). What each
calibration names, with the base and written models' held-out RMSE.

Usage: ``PYTHONPATH=. python docs/bench/session45/falloff_control.py MASTER_SEED`` from a checkout's root.
"""

import importlib
import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports
os.environ["CAMSIM_SEED"] = sys.argv[1]
sim = importlib.import_module("test_independent_sim")
cs = sim.cs
case = sim.CASE_BY_NAME["projection_falloff_unnamed"]

for falloff_kept in (True, False):
    seed, rng, camera = sim.case_camera(case)
    # the case's render draws the overlay's transparency, then the falloff, then the pairs
    digital_alpha, falloff = rng.uniform(0.4, 0.6), rng.uniform(0.6, 0.8)
    pairs = cs.light_projection_pairs(
        rng, camera, sim.N_PAIRS, digital_alpha=digital_alpha, falloff=falloff if falloff_kept else 0.0
    )
    with tempfile.TemporaryDirectory() as root:
        cs.write_pairs(Path(root) / "pairs", pairs)
        report = sim.calibrate(
            sim.CalibrateConfig(
                attack=case.attack,
                measured=str(Path(root) / "pairs"),
                out=str(Path(root) / "out"),
                seed=seed % 2**31,
            )
        )
    print(
        f"master seed {sys.argv[1]} case seed {seed} falloff {falloff if falloff_kept else 0.0:.3f} "
        f"(alpha {digital_alpha:.3f}): named {sorted(sim.named_causes(report))}, held-out "
        f"{report['base']['heldout_rmse']:.3f} -> {report['extended']['heldout_rmse']:.3f}, structure: "
        f"{report['unexplained_structure']['summary'][:160]}",
        flush=True,
    )
