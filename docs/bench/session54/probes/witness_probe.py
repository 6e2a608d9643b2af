"""The multi-pulse step on the bracketed table, fitted from a 46 us start as the tests do, on several noise seeds:
the fitted threshold, its squared error against the truth's, and whether it reaches the floor of the 28.85-37.5 us
flat (the tests' criterion). Exposures are the first argument: "79,246,765,2375" is the strict xfail's table (one
row witnesses the step), "79,246,765,2375,2900" the new test's (three rows).

Usage: ``STRIPES_SEED=1 OMP_NUM_THREADS=1 PYTHONPATH=. python docs/bench/session54/probes/witness_probe.py EXPOSURES SEED...``
(STRIPES_SEED only lets the test module import; the noise seed is each SEED, drawn as ``[SEED, 53]``).
"""

import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

from lerobot_phantom.calibration.core import Fit

exposures = tuple(float(e) for e in sys.argv[1].split(","))
three_short_pulses = 3 * 0.01 / 1040.0
for seed in (int(s) for s in sys.argv[2:]):
    with tempfile.TemporaryDirectory() as tmp:
        truth, problem, fit = ts.fit_from_threshold_start(
            Path(tmp), np.random.default_rng([seed, 53]), 46.0, exposures_us=exposures
        )
        items = np.arange(problem.n_items)
        error = float(np.sum(problem.residual(fit, items) ** 2))
        truth_error = float(np.sum(problem.residual(Fit(fit.effects, truth, {"frames": "lit"}), items) ** 2))
        # the rows that tell the two flats apart: predicted lit at the camera's 30 us, dark at 40 us
        counts = []
        for threshold in (30e-6, 40e-6):
            moved = {**truth, "threshold_s": threshold}
            moved["integration_offset_s"] += 2 * (threshold - truth["threshold_s"])
            values = {k: torch.tensor(v, dtype=torch.float64) for k, v in moved.items()}
            counts.append(problem.predict(fit.effects, values, items, "lit").numpy())
        witnesses = int(np.sum(np.abs(counts[0] - counts[1]) > 5.0))
        reached = (
            fit.extra["frames"] == "lit"
            and three_short_pulses < fit.params["threshold_s"] <= 1.02 * three_short_pulses
        )
        print(
            f"noise seed {seed}: {witnesses} witness rows of {problem.n_items}; threshold "
            f"{fit.params['threshold_s'] * 1e6:.2f} us, squared error {error:.1f} (truth {truth_error:.1f}): "
            + ("reaches the floor" if reached and error <= 1.5 * truth_error else "stays")
        )
