"""How a camsim case's written model's squared error on its fit pairs moves when each parameter is moved alone, and
how many of the laser capture's pixels are saturated (a beam width behind a saturated core acts only where some are).

Usage: ``PYTHONPATH=. python docs/bench/session81/flat_params.py CASE_DIR...`` (a case folder of a matrix run: its
``pairs/`` and ``out/report.json``). Per parameter: the change of the fit pairs' squared error (grey levels^2) at
moves of -1, -0.1, -0.001, +0.001, +0.1, +1 search scales (clipped to the bounds).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import Fit, seeded_split

MOVES = (-1.0, -0.1, -0.001, 0.001, 0.1, 1.0)


def main() -> None:
    for case in map(Path, sys.argv[1:]):
        report = json.loads((case / "out" / "report.json").read_text())
        config = CalibrateConfig(
            attack=report["attack"],
            measured=str(case / "pairs"),
            out=str(case / "unused"),
            seed=report["split"]["seed"],
        )
        problem = build_problem(config)
        items, _ = seeded_split(problem.n_items, config.heldout, config.seed)
        # the written model refitted from its reported parameters, so its per-item nuisances (fit.extra) exist
        fit = problem.fit(frozenset(report["extended"]["effects"]), items, None)
        fit = Fit(fit.effects, dict(report["extended"]["params"]), fit.extra)
        total, _ = problem.squared_errors(fit, items)
        patterns = sorted((case / "pairs").glob("pattern_*.png"))
        peaks = [np.asarray(Image.open(p)) for p in patterns]
        print(
            f"{case}: {len(patterns)} captures, brightest values per channel {peaks[0].max(axis=(0, 1)).tolist()}, "
            f"saturated pixels per channel {[int((q == 255).sum()) for q in np.moveaxis(peaks[0], -1, 0)]} "
            f"(first capture); fit pairs' squared error {total:.6g}"
        )
        specs = {s.name: s for s in problem.param_specs(fit.effects)}
        for name, value in fit.params.items():
            spec = specs[name]
            changes = []
            for move in MOVES:
                moved = min(max(value + move * spec.scale, spec.low), spec.high)
                changes.append(
                    problem.squared_errors(Fit(fit.effects, {**fit.params, name: moved}, fit.extra), items)[0]
                    - total
                )
            interval = report["extended"]["param_intervals"][name]
            print(
                f"  {name} = {value:.6g} [{interval['low']:.6g}, {interval['high']:.6g}]: "
                + ", ".join(f"{m:+g}: {c:+.3g}" for m, c in zip(MOVES, changes, strict=True))
            )


if __name__ == "__main__":
    main()
