"""How far a blur spreads across its fitted path (``BlurFrames.across_share``, the rule that a resonance is a path):
per camsim blur case and master seed, the case's frames are rendered as the test renders them, the resonance
(``sinusoidal_motion``, alone and with ``sensor_gamma``) is fitted on the calibration's fit pairs, and the share of
the path's length that a uniform spread across it takes is printed.

Usage: ``PYTHONPATH=. python docs/bench/session83/across_share.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.frame_models.ultrasound_blur import ACROSS_SHARE_LIMIT

MODELS = (frozenset({"sinusoidal_motion"}), frozenset({"sinusoidal_motion", "sensor_gamma"}))


def print_per_model(label: str, problem, items, measure) -> None:
    """Fit each of ``MODELS`` on ``items`` and print its path's length and what ``measure(problem, fit, items)``
    says of the fit, timed."""
    for effects in MODELS:
        fit = problem.fit(effects, items)
        began = time.perf_counter()
        said = measure(problem, fit, items)
        length = float(np.hypot(fit.params["dx_ref_px"], fit.params["dy_ref_px"]))
        print(
            f"{label} {'+'.join(sorted(effects))}: path {length:.1f} px, {said} "
            f"({time.perf_counter() - began:.2f} s)",
            flush=True,
        )


def print_shares(label: str, problem, items, _camera) -> None:
    """Fit each of ``MODELS`` on ``items`` and print its path's length and the spread across it."""
    print_per_model(
        label,
        problem,
        items,
        lambda problem, fit, items: f"across {problem.across_share(fit, items):.3f} of it",
    )


def each_case_draw(print_draw, heading: str) -> None:
    """``print_draw(label, problem, fit items, camera)`` for every case and master seed the command line names (the
    label names the camera's tone curve)."""
    cases, seeds = sys.argv[1].split(","), [int(s) for s in sys.argv[2:]]
    print(heading)
    for name in cases:
        for master, sim, _case, case_seed, _rng, camera in case_draws(name, seeds):
            with tempfile.TemporaryDirectory() as folder:
                problem, items = sim.drawn_problem(name, case_seed, Path(folder))
                print_draw(f"{name} master {master} ({camera.tone})", problem, items, camera)


def main() -> None:
    each_case_draw(print_shares, f"limit {ACROSS_SHARE_LIMIT}")


if __name__ == "__main__":
    main()
