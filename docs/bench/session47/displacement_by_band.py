"""Per pair of a camsim case under its written model: the displacement d = -sum(r g) / sum(g^2) (pixels; r the
residual predicted - measured, g the prediction's gradient) over the frame, and by eighths of the frame across the
lines (for "along columns": bands of rows), the pairs the report's structure test read (held-out and cross-fitted).

Usage (from a checkout's root): ``PYTHONPATH=. CAMSIM_SEED=0 python3 docs/bench/session47/displacement_by_band.py
CASE MASTER_SEED...``.
"""

import itertools
import sys

import numpy as np

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

import lerobot_phantom.calibration.frame_models.common as common

calls = []
original = common.line_terms


def recording(residual, predicted):
    calls.append((np.asarray(residual, np.float64), np.asarray(predicted, np.float64)))
    return original(residual, predicted)


common.line_terms = recording
name = sys.argv[1]
for seed in sys.argv[2:]:
    calls.clear()
    sim, result = run_on_master_seed(name, seed)
    tests = {t["variable"]: t for t in result["report"]["unexplained_structure"]["tests"]}
    print(f"{name} {seed}", flush=True)
    for direction, axis, across in (("rows", 2, 1), ("columns", 1, 2)):
        t = tests[f"displacement_along_{direction}"]
        print(
            f"  along {direction}: share {t['value']:.3f} (90% {t['interval']['low']:.3f}-{t['interval']['high']:.3f})"
            f" significant {t['significant']}"
        )
        for residual, predicted in calls[-8:]:  # the structure test's sample: the last eight pairs read
            g = np.gradient(predicted, axis=axis)
            d = -np.sum(residual * g) / np.sum(g * g)
            edges = np.linspace(0, residual.shape[across], 9).astype(int)
            bands = []
            for lo, hi in itertools.pairwise(edges):
                part = [slice(None)] * 3
                part[across] = slice(lo, hi)
                bands.append(-np.sum(residual[tuple(part)] * g[tuple(part)]) / np.sum(g[tuple(part)] ** 2))
            print(f"    d {d:+.3f} px; by eighth across the lines {np.round(bands, 2).tolist()}")
