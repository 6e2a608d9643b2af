"""Probe: would a magnitude (|residual|) dependence test separate nulls from zero-mean unnamed effects?

Usage (from a checkout's root): ``PYTHONPATH=. CAMSIM_SEED=0 python3 docs/bench/session46/magnitude_probe.py CASE[,CASE...] MASTER_SEED...``.
A probe of session 46, run before the test was written; its output is beside it.
"""

import sys

import numpy as np

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

import lerobot_phantom.calibration.report as report_mod
from lerobot_phantom.calibration import structure as st
from lerobot_phantom.calibration.core import bin_index

captured = {}
original = report_mod.residual_structure


def patched(problem, fit, items, **kw):
    out = original(problem, fit, items, **kw)
    rng = np.random.default_rng(0)
    sample = problem.residual_sample(fit, items, rng)
    if sample is not None and kw.get("fit_items") is not None and len(items) < st.MIN_TESTED_ITEMS:
        splits = st.kfold(kw["fit_items"], kw["folds"], kw["seed"] + 1)
        sample = sample.joined(st.cross_fitted_sample(problem, fit, splits, rng))
    res = np.concatenate(sample.residual)
    mag = np.abs(res)
    stats = {}
    for name, per in sample.covariates.items():
        v = np.concatenate(per)
        b, _ = bin_index(v, st.BINS)
        n = int(b.max()) + 1
        means = np.array([mag[b == k].mean() if np.any(b == k) else 0 for k in range(n)])
        counts = np.bincount(b, minlength=n)
        eta = float(np.sum(counts * (means - mag.mean()) ** 2) / np.sum((mag - mag.mean()) ** 2))
        # per item (frame) eta, then the median: structure present within frames
        stats[name] = round(eta, 3)
    captured["mag"] = stats
    captured["rms"] = float(np.sqrt(np.mean(res**2)))
    return out


report_mod.residual_structure = patched
cases = sys.argv[1].split(",")
for seed in sys.argv[2:]:
    for name in cases:
        sim, result = run_on_master_seed(name, seed)
        rep = result["report"]
        print(
            f"{name:32s} {seed} named {sorted(sim.named_causes(rep))} structure {'Y' if sim.unexplained_structure(rep) else 'n'} rms {captured['rms']:.2f} |r| eta2 {captured['mag']}",
            flush=True,
        )
