"""Probe: does the residual's variance, standardised by the fitted noise model, depend on row/column/channel/intensity?

Usage (from a checkout's root): ``PYTHONPATH=. CAMSIM_SEED=0 python3 docs/bench/session46/variance_probe.py CASE[,CASE...] MASTER_SEED...``.
A probe of session 46, run before the test was written; its output is beside it.
"""

import sys

import numpy as np
import torch

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

import lerobot_phantom.calibration.cli as cli_mod
from lerobot_phantom.calibration import noise as nz
from lerobot_phantom.calibration.core import bin_index

captured = {}
original = nz.select_shot_noise


def eta2(values, bins):
    n = int(bins.max()) + 1
    counts = np.bincount(bins, minlength=n)
    means = np.bincount(bins, weights=values, minlength=n) / np.maximum(counts, 1)
    return float(np.sum(counts * (means - values.mean()) ** 2) / np.sum((values - values.mean()) ** 2)), means


def patched(problem, fit, fit_items, heldout_items, **kw):
    out = original(problem, fit, fit_items, heldout_items, **kw)
    rng = np.random.default_rng(kw["seed"] + 3)
    curve = nz.tone_curve(fit)
    parts = []
    for i in np.concatenate([fit_items, heldout_items]):
        pair = problem.pairs[int(i)]
        with torch.no_grad():
            image = 255.0 * problem.predict_pair(fit, int(i)).numpy()
        _, H, W = image.shape
        predicted, detail = image.ravel(), nz.local_detail(image).ravel()
        measured = 255.0 * pair.attacked.numpy().ravel()
        usable = np.flatnonzero((predicted > 3) & (predicted < 252) & (measured > 0.5) & (measured < 254.5))
        if len(usable) > 4000:
            usable = np.sort(rng.choice(usable, 4000, replace=False))
        signal, slope = nz.linearise(predicted[usable], curve)
        c, y, x = np.unravel_index(usable, image.shape)
        parts.append(
            (
                nz.NoiseSample(signal, slope, detail[usable], measured[usable] - predicted[usable]),
                y / (H - 1),
                x / (W - 1),
                c,
                np.full(len(usable), pair.intensity),
            )
        )
    fitted = nz.NoiseSample.join([p[0] for p in parts])
    coef = nz.fit_variance(fitted, True)
    z2 = fitted.residual**2 / nz.model_variance(fitted, coef)
    stats = {}
    for k, name in enumerate(("row", "column", "channel", "intensity")):
        v = np.concatenate([p[k + 1] for p in parts])
        b, _ = bin_index(v, 8)
        e, means = eta2(z2, b)
        stats[name] = (round(e, 3), round(float(means.max()), 2))
    captured["stats"] = stats
    return out


cli_mod.select_shot_noise = patched
cases = sys.argv[1].split(",")
for seed in sys.argv[2:]:
    for name in cases:
        sim, result = run_on_master_seed(name, seed)
        rep = result["report"]
        print(
            f"{name:30s} {seed} named {sorted(sim.named_causes(rep))} struct {'Y' if sim.unexplained_structure(rep) else 'n'} z2 eta2,maxbin {captured.get('stats')}",
            flush=True,
        )
        captured.clear()
