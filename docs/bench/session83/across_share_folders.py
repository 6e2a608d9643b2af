"""``across_share.py`` for frame-pair folders already rendered (session 82's ``out_of_library_probe.py`` writes one
per form and seed, ``FOLDER/pairs``): the resonance fitted on the fit pairs of the CLI's default seed, alone and with
``sensor_gamma``, and the share of its path's length a uniform spread across it takes.

Usage: ``PYTHONPATH=. python docs/bench/session83/across_share_folders.py FOLDER...``
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from across_share import print_shares

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import seeded_split


def main() -> None:
    for folder in map(Path, sys.argv[1:]):
        cfg = CalibrateConfig(
            attack="ultrasound_blur", measured=str(folder / "pairs"), out=str(folder / "unused")
        )
        problem = build_problem(cfg)
        items, _ = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
        print_shares(folder.name, problem, items)


if __name__ == "__main__":
    main()
