"""The meter's power and the frames' exposure spread that a model with ``frame_exposure`` fits on a camsim laser
blinding case's fit pairs (the CLI's split), and whether ``identification_checks`` lets the frames' exposures be
named beside that meter.

Usage: ``PYTHONPATH=. python docs/bench/session68/meter_and_spread.py CASE EFFECT+EFFECT+... SEED...`` (the effects
of the model fitted, ``frame_exposure`` among them).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames


def main() -> None:
    import camsim

    name, effects, masters = sys.argv[1], frozenset(sys.argv[2].split("+")), [int(s) for s in sys.argv[3:]]
    defaults = CalibrateConfig()
    for master, _sim, case, seed, rng, camera in case_draws(name, masters):
        with tempfile.TemporaryDirectory() as tmp:
            camsim.write_pairs(Path(tmp), case.render(rng, camera))
            problem = BlindingFrames(load_pairs(Path(tmp), max_side=defaults.max_side), seed % 2**31)
        fit_items, _ = seeded_split(problem.n_items, defaults.heldout, seed % 2**31)
        fit = problem.fit(effects, fit_items)
        exposures = np.round(fit.extra["frame_log_exposure"], 3).tolist()
        check = problem.identification_checks("frame_exposure", fit, fit_items)
        print(
            f"{master} {name} ({camera.tone}): {'+'.join(sorted(effects))} on the fit pairs: meter power "
            f"{fit.params['auto_exposure']:.3f}, exposure spread {fit.params['exposure_spread']:.3f} (frames' "
            f"registered log exposures {exposures}); {'named beside it' if not check else 'not named: ' + check[0]}",
            flush=True,
        )


if __name__ == "__main__":
    main()
