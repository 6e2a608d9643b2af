"""The drift fit's steps on one drift-test draw, with whatever fitting code is imported (PYTHONPATH selects a
checkout): the locked model fitted first (interior rule) and each recording's best value on the first drift grid at
its readout; the fitted model (its drifts, the ones locked for want of evidence, its row time) and every row's
residual; and one recording's fit-row squared error along the grid at the fitted row time.

    python docs/bench/session38/drift_grid_trace.py SEED START EFFECTS RECORDING
    e.g. 1002 entry exposure_overlap,phase_drift,drift_from_entry 0
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
os.environ.setdefault("STRIPES_SEED", "0")
os.environ.setdefault("HF_HUB_OFFLINE", "1")

import test_stripes as ts

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.stripes import DRIFT_EFFECTS, DRIFT_GRID, StripeProblem


def main(seed: int, start_at: str, effects: frozenset[str], recording: int) -> None:
    rng, camera, drifts = ts.drifting_draw(seed, drifting=True)
    table = Path(tempfile.mkdtemp()) / "drifting.csv"
    ts.drifting_table(table, camera, rng, drifts, start_at=start_at)
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    fit_items, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
    print(
        f"STRIPES_SEED={seed} {start_at}: truth drifts {np.round(drifts, 3)}, row time {camera['row_time']:.4g} s"
    )

    base = problem.fit_rules(effects - set(DRIFT_EFFECTS), fit_items, None, ("interior",))
    print(f"locked model (interior): row time {base.params['row_time_s']:.4g} s")
    curve = drift_curves(problem, effects, base.params, fit_items)
    for index, name in enumerate(problem.drift_names):
        errors = curve[:, index]
        print(
            f"  first grid, {name}: best {DRIFT_GRID[np.argmin(errors)]:.3f}, error {errors[0]:.1f} at 0, "
            f"{errors.min():.1f} at best"
        )

    fit = problem.fit(effects, fit_items)
    print(
        f"fitted: row time {fit.params['row_time_s']:.4g} s, locked for want of evidence "
        f"{fit.extra.get('drifts_locked_for_want_of_evidence')}"
    )
    print("  drifts " + ", ".join(f"{n}={fit.params[n]:.3f}" for n in problem.drift_names))
    residual = problem.residual(fit, np.arange(problem.n_items))
    for item, value in enumerate(residual):
        role = "held-out" if item in heldout else "fit"
        print(
            f"  exposure {problem.exposure_setting[item]:g} duty {problem.duty[item]:.2f} measured "
            f"{problem.rows[item]:.1f} residual {value:+.2f} {role}"
        )
    print(f"  held-out RMSE {problem.rmse(fit, heldout):.2f} rows")

    shared = {k: v for k, v in fit.params.items() if k not in problem.drift_names}
    errors = drift_curves(problem, effects, shared, fit_items)[:, recording]
    print(f"{problem.drift_names[recording]} along the grid at the fitted row time (others at 0):")
    for value, error in zip(DRIFT_GRID, errors, strict=True):
        print(f"  {value:.3f}: {error:.1f}")


def drift_curves(problem, effects, shared: dict, items: np.ndarray) -> np.ndarray:
    """(grid, recordings): each recording's fit rows' squared error at each grid drift, the others' at the same."""
    values = {
        k: torch.tensor(v, dtype=torch.float64) for k, v in shared.items() if k not in problem.drift_names
    }
    grid = torch.as_tensor(DRIFT_GRID)
    with torch.no_grad():
        predicted = problem.predict(
            effects, values | {n: grid for n in problem.drift_names}, items, "interior"
        )
    squared = ((predicted - torch.as_tensor(problem.rows[items])) ** 2).numpy()
    recordings = problem.recording[items]
    return np.stack([squared[:, recordings == k].sum(1) for k in range(len(problem.drift_names))], axis=1)


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2], frozenset(sys.argv[3].split(",")), int(sys.argv[4]))
