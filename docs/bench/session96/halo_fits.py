"""camsim's blinding_halo case: the written model and the same model with the halo, fitted on the fit pairs,
each one's parameters and its fit and held-out RMSE per pair (session 96).

Usage: ``PYTHONPATH=. python docs/bench/session96/halo_fits.py PAIRS_DIR SPLIT_SEED EFFECTS...`` (a case's
``pairs`` folder under a camsim run's basetemp, its report's ``split.seed``; each EFFECTS a '+'-joined group).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames


def case_problem(folder: Path, seed: int) -> tuple[BlindingFrames, np.ndarray, np.ndarray]:
    """A case's pairs as the CLI reads them, and its fit and held-out items under split seed ``seed``."""
    defaults = CalibrateConfig()
    problem = BlindingFrames(load_pairs(folder, max_side=defaults.max_side), seed)
    return problem, *seeded_split(problem.n_items, defaults.heldout, seed)


def main() -> None:
    problem, fit_items, held = case_problem(Path(sys.argv[1]), int(sys.argv[2]))
    for group in sys.argv[3:]:
        effects = frozenset(group.split("+"))
        fit = problem.fit(effects, fit_items)
        per_pair = {int(i): round(problem.rmse(fit, np.array([i])), 2) for i in range(problem.n_items)}
        print(
            f"{group}: fit {problem.rmse(fit, fit_items):.3f} held-out {problem.rmse(fit, held):.3f}; "
            f"{ {k: round(v, 4) for k, v in fit.params.items()} }\n  per pair {per_pair} (held-out {held.tolist()})"
        )


if __name__ == "__main__":
    main()
