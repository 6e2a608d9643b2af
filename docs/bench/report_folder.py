"""A calibration's report folder (``FOLDER/pairs`` beside ``FOLDER/out/report.json``) read back as the CLI read it,
for bench scripts that replay a rule or a simulation on what a calibration saw."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import Problem, seeded_split


def report_problem(folder: Path, attack: str) -> tuple[dict, Problem, np.ndarray, np.ndarray]:
    """The folder's report, the problem built from its pairs, and the report's fit and held-out items (its split
    seed, the CLI's held-out share)."""
    report = json.loads((folder / "out" / "report.json").read_text())
    cfg = CalibrateConfig(
        attack=attack, measured=str(folder / "pairs"), out=str(folder / "out"), seed=report["split"]["seed"]
    )
    problem = build_problem(cfg)
    fit_items, heldout = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
    return report, problem, fit_items, heldout
