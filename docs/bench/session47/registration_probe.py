"""Probe: does the written model's residual follow the prediction's spatial gradient (an image displaced by a
fraction of a pixel or more: ``r ~ -shift * dI/dx``)? Globally, and with one shift per row of each frame.

Usage (from a checkout's root): ``PYTHONPATH=. CAMSIM_SEED=0 python3 docs/bench/session47/registration_probe.py
CASE[,CASE...] MASTER_SEED...``. A probe of session 47, run before any test was written; its output is beside it.
All eight pairs of a case under the written model (fit items included: a probe, not the report's sample).
"""

import sys

import numpy as np
import torch

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

import lerobot_phantom.calibration.report as report_mod

captured = {}
original = report_mod.residual_structure


def patched(problem, fit, items, **kw):
    captured["problem"], captured["fit"] = problem, fit
    return original(problem, fit, items, **kw)


report_mod.residual_structure = patched


def gradients(image):
    gx = np.zeros_like(image)
    gy = np.zeros_like(image)
    gx[:, :, 1:-1] = (image[:, :, 2:] - image[:, :, :-2]) / 2
    gy[:, 1:-1] = (image[:, 2:] - image[:, :-2]) / 2
    return gx, gy


def stats(problem, fit):
    r_all, gx_all, gy_all = [], [], []
    row_share_num, chance = 0.0, 0.0
    total_sq = 0.0
    for i in range(problem.n_items):
        pair = problem.pairs[i]
        with torch.no_grad():
            pred = 255.0 * problem.predict_pair(fit, i).numpy()
        r = pred - 255.0 * pair.attacked.numpy()
        gx, gy = gradients(pred)
        inner = np.s_[:, 1:-1, 1:-1]
        r, gx, gy = r[inner], gx[inner], gy[inner]
        r_all.append(r.ravel())
        gx_all.append(gx.ravel())
        gy_all.append(gy.ravel())
        # one coefficient per row (channels pooled): explained sum of squares
        num = np.sum(r * gx, axis=(0, 2))
        den = np.maximum(np.sum(gx * gx, axis=(0, 2)), 1e-12)
        row_share_num += float(np.sum(num**2 / den))
        chance += r.shape[1]
        total_sq += float(np.sum(r**2))
    r, gx, gy = (np.concatenate(v) for v in (r_all, gx_all, gy_all))
    n = len(r)
    return {
        "corr_gx": round(float(np.corrcoef(r, gx)[0, 1]), 3),
        "corr_gy": round(float(np.corrcoef(r, gy)[0, 1]), 3),
        "row_shift_share": round(row_share_num / total_sq, 4),
        "row_chance": round(chance / n, 4),
        "rms": round(float(np.sqrt(np.mean(r**2))), 2),
    }


cases = sys.argv[1].split(",")
for seed in sys.argv[2:]:
    for name in cases:
        sim, result = run_on_master_seed(name, seed)
        rep = result["report"]
        s = stats(captured["problem"], captured["fit"])
        print(
            f"{name:30s} {seed} effects {rep['extended']['effects']} struct "
            f"{'Y' if sim.unexplained_structure(rep) else 'n'} {s}",
            flush=True,
        )
        captured.clear()
