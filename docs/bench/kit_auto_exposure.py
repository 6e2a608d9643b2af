"""The calibration test kit's hidden auto-exposure case over seeds: is ``auto_exposure`` named, its power recovered?

Usage: ``PYTHONPATH=. python docs/bench/kit_auto_exposure.py TESTS_DIR SEED...`` (TESTS_DIR holds
``calibration_testkit.py``). Each seed renders the case as ``test_hidden_effects.py`` does and calibrates it with
the CLI's defaults; prints the drawn meter power, the named effects, the held-out RMSE ratio and the fitted
parameters.
"""

from __future__ import annotations

import importlib
import sys
import tempfile
from pathlib import Path

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main() -> None:
    sys.path.insert(0, sys.argv[1])
    kit = importlib.import_module("calibration_testkit")
    for seed in map(int, sys.argv[2:]):
        with tempfile.TemporaryDirectory() as scratch:
            measured = Path(scratch) / "measured"
            measured.mkdir()
            truth = kit.render_laser_blinding(measured, {"auto_exposure"}, seed)
            report = calibrate(
                CalibrateConfig(
                    attack="laser_blinding", measured=str(measured), out=str(Path(scratch) / "out"), seed=seed
                )
            )
        extended = report["extended"]
        params = {k: round(v, 3) for k, v in extended["params"].items()}
        print(
            f"seed {seed}: drawn power {truth['auto_exposure']:.3f}, named {sorted(extended['effects'])}, "
            f"RMSE ratio {report['gain']['rmse_ratio']:.2f}, fitted {params}",
            flush=True,
        )


if __name__ == "__main__":
    main()
