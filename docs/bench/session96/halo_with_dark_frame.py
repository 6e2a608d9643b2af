"""camsim's blinding_halo draw of a master seed calibrated again with the capture's dark frame (session 96).

``camsim.laser_blinding_pairs(..., dark_frame=True)`` repeats the laser capture with the laser off from a stream of
its own, so every other draw (camera, scenes, laser, glare, noise) is the case's: the pairs are the case's pairs
plus a ``pattern_dark`` column. Calibrated by the CLI with the case's split seed; prints the named causes and the
selection's steps.

    PYTHONPATH=.:tests/calibration:tests python docs/bench/session96/halo_with_dark_frame.py OUTDIR SEED...
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

import numpy as np


def main() -> None:
    out = Path(sys.argv[1])
    for master in map(int, sys.argv[2:]):
        os.environ["CAMSIM_SEED"] = str(master)
        import camsim as cs
        import test_independent_sim as tis

        tis = importlib.reload(tis)
        case = tis.CASE_BY_NAME["blinding_halo"]
        seed, rng, camera = tis.case_camera(case)
        pairs = cs.laser_blinding_pairs(rng, camera, tis.N_PAIRS, halo=True, dark_frame=True)
        folder = out / f"blinding_halo_{master}_dark_frame"
        cs.write_pairs(folder / "pairs", pairs)
        report = tis.calibrate(
            tis.CalibrateConfig(
                attack=case.attack, measured=str(folder / "pairs"), out=str(folder / "out"), seed=seed % 2**31
            )
        )
        steps = " -> ".join(
            f"{'+'.join(s['effects']) or 'base'} {s['validation_error']:.2f}"
            for s in report["selection"]["steps"]
        )
        print(
            f"master {master} (case seed {seed}, tone {camera.tone}): named {sorted(tis.named_causes(report))}; "
            f"held-out written {report['extended']['heldout_rmse']:.2f}; steps {steps}"
        )
        np.testing.assert_equal(len(pairs), tis.N_PAIRS)


if __name__ == "__main__":
    main()
