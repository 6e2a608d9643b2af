"""camsim ``blinding_halo`` draws: linear light alone, and with the power-law glare twice: as the package composes it
(inside the area the laser capture measured, the glare its dark level took out is added back: the halo at the dark
level's distance) and without that share (the glare only where the capture did not measure). Fitted on the CLI's
fit pairs (its split seed, from the case's report); fit pairs' / held-out RMSE (grey levels), the halo's parameters.

Usage: ``PYTHONPATH=. python docs/bench/session79/halo/addback_survey.py CASE_DIR...`` (a case folder of a camsim
run: ``pairs/`` and ``out/report.json``)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import seeded_split, single_threaded
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames

LINEAR = frozenset({"linear_light_saturation"})
HALO = LINEAR | {"halo_power_law"}


def survey(case: Path) -> str:
    report = json.loads((case / "out" / "report.json").read_text())
    seed = report["split"]["seed"]
    defaults = CalibrateConfig()
    problem = BlindingFrames(load_pairs(case / "pairs", max_side=defaults.max_side), seed)
    fit_items, heldout = seeded_split(problem.n_items, defaults.heldout, seed)
    line = [f"{case.parent.parent.name}: named {report['extended']['effects']}"]
    with single_threaded():
        linear = problem.fit(LINEAR, fit_items)
        line.append(f"linear light {problem.rmse(linear, fit_items):.2f}/{problem.rmse(linear, heldout):.2f}")
        for label in ("with the dark level's share", "without it"):
            if label == "without it":
                # the halo at an unreachable distance: no glare added where the capture measured
                problem.dark_radii = [1e9] * len(problem.dark_radii)
            fit = problem.fit(HALO, fit_items, start=linear)
            p = fit.params
            line.append(
                f"halo {label}: {problem.rmse(fit, fit_items):.2f}/{problem.rmse(fit, heldout):.2f}, level "
                f"{p['halo_level']:.3f}, exponent {p['halo_exponent']:.2f}, log10 gain {p['log10_gain']:.3f}"
            )
    return "; ".join(line)


def main() -> None:
    print(
        "# RMSE: fit pairs / held-out (grey levels); the halo's level is at 64 reference px, its bounds 0-5"
    )
    for case in sys.argv[1:]:
        print(survey(Path(case)), flush=True)


if __name__ == "__main__":
    main()
