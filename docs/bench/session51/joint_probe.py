"""Stripe selection with groups of up to JOINT new effects per step (``StripeProblem.joint_effects``): per case, the
written model, its held-out RMSE, the selection path (each step's effects and cross-validated score) and the
calibration's CPU time in this process.

A case is ``SEED:lit`` or ``SEED:interior`` (``test_stripes.py``'s drawn second camera, the test's flags) or
``logitech=PATH`` (the Logitech table as ``test_logitech_stripes`` runs it: 720 rows, exposure unit 1e-4 s).

Usage: ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session51/joint_probe.py JOINT CASE...``
"""

import importlib
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path("tests/calibration").resolve()))
sys.path.insert(0, str(Path("tests").resolve()))

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.stripes import StripeProblem


def run(case: str) -> tuple[str, dict]:
    with tempfile.TemporaryDirectory() as root:
        if case.startswith("logitech="):
            config = CalibrateConfig(
                attack="laser_color_strip",
                measured=case.split("=", 1)[1],
                out=str(Path(root) / "out"),
                image_height=720,
                exposure_unit_s=1e-4,
            )
            return "logitech", calibrate(config)
        seed, frames = case.split(":")
        os.environ["STRIPES_SEED"] = seed
        import test_stripes

        module = importlib.reload(test_stripes)
        style = "exposure" if frames == "interior" else "exposure_us"
        _camera, report = module.calibrate_drawn_camera(
            Path(root), int(seed), frames, style, calibration_seed=int(seed) % 1000
        )
        return f"{seed} {frames}", report


def main() -> None:
    StripeProblem.joint_effects = int(sys.argv[1])
    for case in sys.argv[2:]:
        start = time.process_time()
        name, report = run(case)
        cpu = time.process_time() - start
        extended = report["extended"]
        path = " -> ".join(
            f"{'+'.join(step['effects']) or 'base'} {step['validation_error']:.2f}"
            for step in report["selection"]["steps"]
        )
        print(
            f"joint {StripeProblem.joint_effects} {name:20s} held-out {extended['heldout_rmse']:8.2f} "
            f"written {'+'.join(sorted(extended['effects']))} withdrawn {report['selection'].get('withdrawn')} "
            f"cpu {cpu:6.1f} s | {path}",
            flush=True,
        )


if __name__ == "__main__":
    main()
