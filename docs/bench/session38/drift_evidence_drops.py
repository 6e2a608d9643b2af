"""Each recording's drift evidence (``StripeProblem.drifts_without_evidence``'s variance-weighted drop in its fit rows'
squared error against a lock, in total, without its largest row, and per row) at the drift fit's joint optimum, before the rule locks any: on the Axis table's
splits, the Logitech table's split 0 and the entry-drift test's draw 1002. Prints the drift and the drop per recording.

    python docs/bench/session38/drift_evidence_drops.py AXIS_CSV LOGITECH_CSV
"""

import os
import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
os.environ.setdefault("STRIPES_SEED", "0")

import lerobot_phantom.calibration.stripes as stripes
from lerobot_phantom.calibration.core import seeded_split, single_threaded

EFFECTS = frozenset({"exposure_overlap", "integration_offset", "phase_drift", "drift_from_entry"})
evidence = stripes.StripeProblem.drifts_without_evidence


def report_drops(self, effects, params, items):
    values = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
    with torch.no_grad():
        fitted = self.predict(effects, values, items, "interior").numpy()
    measured = self.standard_error[items] ** 2
    model = max(float(np.mean((fitted - self.rows[items]) ** 2 - measured)), 1e-9)
    recordings = self.recording[items]
    for index, name in enumerate(self.drift_names):
        drift = params[name]
        if drift <= 0.0:
            continue
        with torch.no_grad():
            locked = self.predict(
                effects, values | {name: torch.tensor(0.0, dtype=torch.float64)}, items, "interior"
            )
        mine = recordings == index
        drop = ((locked.numpy() - self.rows[items]) ** 2 - (fitted - self.rows[items]) ** 2) / (
            model + measured
        )
        rows = np.sort(drop[mine])[::-1]
        print(
            f"    {name}: drift {drift:.3f}, drop {rows.sum():.2f} over {mine.sum()} fit rows; without its largest "
            f"row {rows[1:].sum():.2f}; per row {np.round(rows, 2).tolist()}"
        )
    locked_names = evidence(self, effects, params, items)
    print(f"    locked by the rule ({stripes.DRIFT_EVIDENCE}): {locked_names}", flush=True)
    return locked_names


stripes.StripeProblem.drifts_without_evidence = report_drops


def run(label, table, height, unit, seed, effects=EFFECTS):
    problem = stripes.StripeProblem(Path(table), image_height=height, exposure_unit_s=unit)
    fit_items, heldout = seeded_split(problem.n_items, 0.2, seed)
    print(f"{label} split {seed}:", flush=True)
    fit = problem.fit(effects, fit_items)
    print(f"  held-out {problem.rmse(fit, heldout):.2f} rows", flush=True)


def main() -> None:
    axis, logitech = sys.argv[1:3]
    with single_threaded():
        for seed in (3, 6, 2):
            run("Axis", axis, 720, 1e-6, seed)
        run("Logitech", logitech, 720, 1e-4, 0)
        import tempfile

        import test_stripes as ts

        rng, camera, drifts = ts.drifting_draw(1002, drifting=True)
        table = Path(tempfile.mkdtemp()) / "drifting.csv"
        ts.drifting_table(table, camera, rng, drifts, start_at="entry")
        run(
            f"draw 1002 (drifts {np.round(drifts, 3)})",
            table,
            camera["height"],
            None,
            2,
            frozenset({"exposure_overlap", "phase_drift", "drift_from_entry"}),
        )


if __name__ == "__main__":
    main()
