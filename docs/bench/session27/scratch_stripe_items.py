"""Scratch: per-item CV errors of the stripe selection's first pass (which rows carry the threshold's gain)."""

import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import fit_chain, forward_select, seeded_split, single_threaded
from lerobot_phantom.calibration.stripes import StripeProblem

table, height, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
problem = StripeProblem(Path(table), image_height=height, exposure_unit_s=None)
fit, held = seeded_split(problem.n_items, 0.2, seed)
with single_threaded():
    _, steps = forward_select(problem, fit, seed=seed, margin=0.05, folds=4)
    for s in steps:
        print(s.effects, round(s.validation_error, 2), {k: round(v, 2) for k, v in s.tried.items()})
    a, b = steps[0].item_errors, steps[-1].item_errors
    k = [i for i, s in enumerate(steps) if s.effects == ["exposure_overlap", "integration_offset"]]
    mid = steps[k[0]].item_errors if k else None
    on = problem.duty / problem.frequency_hz
    print("item  f  duty  exp_us  on_us  rows  err(overlap+offset)  err(last)")
    order = np.argsort(-(mid - b)) if mid is not None else range(len(fit))
    for j in list(order)[:12]:
        i = fit[j]
        print(
            i,
            problem.frequency_hz[i],
            problem.duty[i],
            round(problem.exposure_s[i] * 1e6),
            round(on[i] * 1e6, 1),
            problem.rows[i],
            round(mid[j], 1) if mid is not None else None,
            round(b[j], 1),
        )
    chain = fit_chain(problem, steps, fit)
    print({k: v for k, v in chain[-1].params.items()}, chain[-1].extra)
    held_err = problem.residual(chain[-1], held)
    print("held-out with the selected model:", np.sqrt(np.mean(held_err**2)))
    for i, e in zip(held, held_err, strict=True):
        print(
            " held",
            i,
            problem.frequency_hz[i],
            problem.duty[i],
            round(problem.exposure_s[i] * 1e6),
            round(on[i] * 1e6, 1),
            problem.rows[i],
            round(e, 1),
        )
