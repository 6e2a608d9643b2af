"""Why camsim's ``projection_sensor_gamma`` case can miss ``sensor_gamma``: fits of a saved case's frame pairs.

Usage: ``PYTHONPATH=. python docs/bench/camsim_projection_diagnosis.py PAIRS_DIR GAMMA``
(PAIRS_DIR: a case's ``pairs`` folder, kept under pytest's ``--basetemp``; GAMMA: a power law to linearise with).
Prints (1) in-sample RMSE of nested projection models on all pairs, (2) the same models fitted on the folds of a
4-fold split of the first six pairs and scored on the held-out fold, (3) per pair and channel, the added light over
(clean x pattern x intensity) in linear light, with a plane fitted over the frame (level, and its x / y slopes
relative to the level): the additive-albedo model assumes that level is one constant for all pairs.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import kfold
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames

MODELS = [
    (),
    ("additive_light",),
    ("additive_light", "albedo_modulation"),
    ("additive_light", "sensor_gamma"),
    ("additive_light", "albedo_modulation", "sensor_gamma"),
    ("additive_light", "albedo_modulation", "sensor_gamma", "channel_crosstalk"),
]
FOLD_MODELS = [
    ("additive_light",),
    ("additive_light", "albedo_modulation", "sensor_gamma"),
    ("additive_light", "albedo_modulation"),
]


def main() -> None:
    folder, gamma = Path(sys.argv[1]), float(sys.argv[2])
    pairs = load_pairs(folder, max_side=4096)
    problem = ProjectionFrames(pairs, seed=0)
    items = np.arange(len(pairs))
    base = problem.fit(frozenset(), items)
    print("(1) in-sample, all pairs")
    for effects in MODELS:
        fit = problem.fit(frozenset(effects), items, start=base)
        params = {k: round(v, 3) for k, v in fit.params.items() if not k.startswith("crosstalk")}
        print(f"  {'+'.join(effects) or 'base'}: RMSE {problem.rmse(fit, items):.2f} {params}")
    print("(2) folds of the first six pairs: held-out RMSE (train RMSE) and parameters")
    for train, val in kfold(items[:6], 4, 1):
        print(f"  train {train.tolist()} validate {val.tolist()}")
        nested = problem.fit(frozenset({"additive_light"}), train, start=problem.fit(frozenset(), train))
        for effects in FOLD_MODELS:
            fit = problem.fit(frozenset(effects), train, start=nested) if len(effects) > 1 else nested
            params = {k: round(v, 2) for k, v in fit.params.items()}
            print(
                f"    {'+'.join(effects)}: {problem.rmse(fit, val):.2f} ({problem.rmse(fit, train):.2f}) {params}"
            )
    print(f"(3) added light / (clean x pattern x intensity), linearised with gamma {gamma:g}")
    for k, pair in enumerate(pairs):
        clean, attacked, pattern = (t.numpy() ** gamma for t in (pair.clean, pair.attacked, pair.pattern))
        height, width = clean.shape[1:]
        yy, xx = np.mgrid[0:height, 0:width] / np.array([height, width])[:, None, None]
        usable = (pattern > 0.05) & (clean > 0.02) & (pair.attacked.numpy() < 0.97)
        with np.errstate(divide="ignore", invalid="ignore"):  # unusable pixels divide by zero; masked below
            ratio = (attacked - clean) / (clean * pattern * pair.intensity)
        fields = []
        for channel in range(3):
            mask = usable[channel]
            design = np.stack([np.ones(mask.sum()), xx[mask] - 0.5, yy[mask] - 0.5], 1)
            coef, *_ = np.linalg.lstsq(design, ratio[channel][mask], rcond=None)
            fields.append(f"ch{channel} {coef[0]:.2f} x {coef[1] / coef[0]:+.2f} y {coef[2] / coef[0]:+.2f}")
        print(f"  pair {k} intensity {pair.intensity:.2f}: " + " | ".join(fields))


if __name__ == "__main__":
    main()
