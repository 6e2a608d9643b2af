"""Nested laser blinding models fitted to one camsim case's fit pairs (the CLI's split), each warm-started from the
previous nested one: the parameters behind a selection path.

Usage: ``PYTHONPATH=. python docs/bench/camsim_blinding_nested_fits.py PAIRS_DIR CASE_SEED [halo|auto_exposure]``
(a case's ``pairs`` folder under a camsim run's basetemp, the case seed its report was calibrated with, and the
paths to fit: the halo case's, the default, or the auto-exposure case's). A model not nested in the one before it
starts from the defaults.
"""

from __future__ import annotations

import sys
from pathlib import Path

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames

LINEAR = "linear_light_saturation"
METER = "auto_exposure"
PATHS = {
    "halo": (
        (LINEAR,),
        (LINEAR, "tone_shoulder"),
        (LINEAR, "tone_shoulder", "halo_power_law"),
        (LINEAR, "tone_shoulder", "halo_power_law", "sensor_gamma"),
        (LINEAR, "halo_power_law"),
        (LINEAR, "halo_power_law", "sensor_gamma"),
    ),
    "auto_exposure": (
        (METER,),
        (METER, LINEAR),
        (METER, LINEAR, "tone_shoulder"),
        (METER, LINEAR, "halo_power_law"),
        (METER, LINEAR, "halo_power_law", "sensor_gamma"),
        (METER, LINEAR, "sensor_gamma"),
    ),
}


def fit_line(problem, fit, fit_items, heldout) -> str:
    """A fit's effects, its RMSE on the fit and the held-out pairs and its parameters, on one line."""
    params = {k: round(v, 3) for k, v in fit.params.items()}
    return (
        f"{'+'.join(sorted(fit.effects))} fit {problem.rmse(fit, fit_items):.3f} "
        f"held {problem.rmse(fit, heldout):.3f} {params}"
    )


def main() -> None:
    folder, seed = Path(sys.argv[1]), int(sys.argv[2]) % 2**31
    paths = PATHS[sys.argv[3] if len(sys.argv) > 3 else "halo"]
    defaults = CalibrateConfig()
    problem = BlindingFrames(load_pairs(folder, max_side=defaults.max_side), seed)
    fit_items, heldout = seeded_split(problem.n_items, defaults.heldout, seed)
    previous = None
    for effects in map(frozenset, paths):
        start = previous if previous is not None and previous.effects <= effects else None
        previous = problem.fit(effects, fit_items, start)
        print(fit_line(problem, previous, fit_items, heldout))


if __name__ == "__main__":
    main()
