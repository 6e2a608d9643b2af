"""What each named cause of a calibration's written model still pays once every other selected effect is in: the
selection's own cross-validated score (its folds, seed and fit items) of the selected model, and of the selected
model without each effect that no other selected effect builds on, with the paired bootstrap ratio of the two.

Usage: ``PYTHONPATH=. python docs/bench/session77/drop_one_probe.py CASE_DIR...`` (a case folder of
``session64/run_camsim_case.py``: ``pairs/`` and ``out/report.json``; the attack is read from the report)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import cross_validated, dependants, seeded_split, selection_folds
from lerobot_phantom.calibration.identify import error_ratio


def probe(case_dir: Path) -> None:
    report = json.loads((case_dir / "out" / "report.json").read_text())
    seed = report["split"]["seed"]
    cfg = CalibrateConfig(attack=report["attack"], measured=str(case_dir / "pairs"), out="unused", seed=seed)
    problem = build_problem(cfg)
    fit_items, _ = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
    splits = selection_folds(fit_items, cfg.folds, cfg.seed, 2500)
    selected = frozenset(report["selection"]["selected"])
    score, _, per_item = cross_validated(problem, selected, splits, None)
    terms = np.array([per_item[int(i)] for i in fit_items])
    print(f"{case_dir}: selected {sorted(selected)}, cross-validated {score:.3f}", flush=True)
    for effect in sorted(selected):
        if dependants(problem, selected, effect) - {effect}:
            continue
        without, _, per_item_without = cross_validated(problem, selected - {effect}, splits, None)
        ratio = error_ratio(
            np.array([per_item_without[int(i)] for i in fit_items]),
            terms,
            rng=np.random.default_rng(0),
            score=problem.selection_score,
        )
        print(
            f"  without {effect}: {without:.3f}, ratio {ratio.estimate:.4f} [{ratio.low:.4f}, {ratio.high:.4f}]",
            flush=True,
        )


if __name__ == "__main__":
    for arg in sys.argv[1:]:
        probe(Path(arg))
