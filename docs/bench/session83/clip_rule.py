"""The clip rule (``ProjectionTerms.identification_checks``) on calibration reports that named ``clipping``: per
report folder (``FOLDER/out/report.json`` beside ``FOLDER/pairs``), the written model's white in grey levels, the
share of the fit pairs' clean pixels above it in every channel, and the rule's verdict.

Usage: ``PYTHONPATH=. python docs/bench/session83/clip_rule.py FOLDER...``
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import Fit, seeded_split


def main() -> None:
    for folder in map(Path, sys.argv[1:]):
        report = json.loads((folder / "out" / "report.json").read_text())
        effects = frozenset(report["extended"]["effects"])
        if "clipping" not in effects:
            print(f"{folder}: no clip named")
            continue
        cfg = CalibrateConfig(
            attack="light_projection",
            measured=str(folder / "pairs"),
            out=str(folder / "unused"),
            seed=report["split"]["seed"],
        )
        problem = build_problem(cfg)
        items, _ = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
        fit = Fit(effects, report["extended"]["params"])
        white, share = problem.white_exceeded(fit, items)
        reasons = problem.identification_checks("clipping", fit, items)
        print(
            f"{folder}: named {sorted(effects)}; white {white:.1f} grey levels, {share:.2%} of the fit pairs' clean "
            f"pixels above it in every channel: {'not the sensor' if reasons else 'kept'}",
            flush=True,
        )


if __name__ == "__main__":
    main()
