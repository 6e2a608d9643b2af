"""The clip rule (``ProjectionTerms.identification_checks``) on calibration reports that named ``clipping``: per
report folder (``FOLDER/out/report.json`` beside ``FOLDER/pairs``), the written model's white in grey levels, the
share of the fit pairs' clean pixels above it in every channel, and the rule's verdict.

Usage: ``PYTHONPATH=. python docs/bench/session83/clip_rule.py FOLDER...``
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from report_folder import report_problem

from lerobot_phantom.calibration.core import Fit


def main() -> None:
    for folder in map(Path, sys.argv[1:]):
        report, problem, items, _ = report_problem(folder, "light_projection")
        effects = frozenset(report["extended"]["effects"])
        if "clipping" not in effects:
            print(f"{folder}: no clip named")
            continue
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
