"""The camera each camsim case draws on given master seeds, exactly as the test draws it (nothing is rendered).

Usage: ``PYTHONPATH=. python docs/bench/camsim_case_cameras.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "calibration"))


def main() -> None:
    cases, seeds = sys.argv[1].split(","), [int(s) for s in sys.argv[2:]]
    for master in seeds:
        os.environ["CAMSIM_SEED"] = str(master)
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        for name in cases:
            _, _, camera = sim.case_camera(sim.CASE_BY_NAME[name])
            gamma = f" {camera.tone_gamma:.2f}" if camera.tone == "power" else ""
            print(f"master {master} {name}: tone {camera.tone}{gamma}, full well {camera.full_well_e:.0f} e")


if __name__ == "__main__":
    main()
