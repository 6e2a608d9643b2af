"""camsim cases under the light-projection tone-curve position check (session 60), one line per master seed.

``PYTHONPATH=. python docs/bench/session60/tone_position_cases.py OUTDIR CASE MASTER_SEED...`` from a checkout's
root: renders ``CASE`` as ``tests/calibration/test_independent_sim.py`` does under each ``CAMSIM_SEED``, calibrates
it with the checkout's package and prints what is named, whether the case passes its test's rule, what was
withdrawn and why (the check's reason starts "the gamma fitted on the pixels nearest"), and, where ``sensor_gamma``
is written, the check's own figures on the written model: the gamma of each position half and the whole frame's
departure from 1 as a multiple of the halves' mean departure (``TONE_POSITION_EXCESS`` is the most it may be).
On a checkout without the check (no ``gamma_by_position``) the figures are left out.
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path.cwd() / "tests" / "calibration"))
sys.path.insert(1, str(Path.cwd() / "tests"))


def passes(sim, case, report: dict, camera) -> bool:
    named = sim.named_causes(report)
    if case.kind == "effect":
        return case.planted <= named and len(named - case.planted - sim.tolerated(case, camera)) <= 1
    if case.kind == "unexplained":
        return not named - sim.tolerated(case, camera) and bool(sim.unexplained_structure(report))
    return not report["extended"]["effects"]


def position_figures(cfg, report: dict) -> str:
    from lerobot_phantom.calibration.cli import build_problem
    from lerobot_phantom.calibration.core import Fit, seeded_split

    problem = build_problem(cfg)
    if not hasattr(problem, "gamma_by_position"):
        return ""
    fit_items, _ = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
    fit = Fit(frozenset(report["extended"]["effects"]), report["extended"]["params"])
    halves = problem.gamma_by_position(fit, fit_items)
    ratio = (fit.params["gamma"] - 1.0) / (np.mean(halves) - 1.0)
    return f" | gamma whole {fit.params['gamma']:.3f} inner {halves[0]:.3f} outer {halves[1]:.3f} ratio {ratio:.2f}"


def main() -> None:
    out, name, seeds = Path(sys.argv[1]), sys.argv[2], sys.argv[3:]
    for master in seeds:
        os.environ["CAMSIM_SEED"] = master
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        from lerobot_phantom.calibration.cli import CalibrateConfig

        case = sim.CASE_BY_NAME[name]
        result = sim.run_case(name, str(out / master))
        report = result["report"]
        cfg = CalibrateConfig(
            attack=case.attack,
            measured=str(out / master / name / "pairs"),
            out=str(out / master / name / "out"),
            seed=result["seed"] % 2**31,
        )
        withdrawn = "; ".join(
            f"{w['effect']}: {w['reasons'][0][:90]}" for w in report["selection"]["withdrawn"]
        )
        figures = position_figures(cfg, report) if "sensor_gamma" in report["extended"]["effects"] else ""
        print(
            f"{name} {master} (case seed {result['seed']}, {result['camera'].tone}) "
            f"{'pass' if passes(sim, case, report, result['camera']) else 'FAIL'} named {sorted(sim.named_causes(report))} "
            f"structure {bool(sim.unexplained_structure(report))} heldout {report['base']['heldout_rmse']:.3f} -> "
            f"{report['extended']['heldout_rmse']:.3f} | withdrawn [{withdrawn}]{figures}",
            flush=True,
        )


if __name__ == "__main__":
    main()
