"""Session 48 scratch probe, run from a checkout's root with that checkout on PYTHONPATH (outputs beside it name
the commit). Per-fold fits and scores of the overlap with an offset against the overlap with a threshold, as selection's first step computes them: ``python tie_probe.py SEED lit|interior``"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

from lerobot_phantom.calibration.core import cross_validated, kfold, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

frames = sys.argv[2]
style = "exposure" if frames == "interior" else "exposure_us"
with tempfile.TemporaryDirectory() as root:
    table = Path(root) / "t.csv"
    camera = ts.drawn_camera_table(table, ts.SEED, frames, style)
    problem = StripeProblem(
        table, image_height=camera["height"], exposure_unit_s=1e-6 if style == "exposure" else None
    )
seed = ts.SEED % 1000
fit_items, held = seeded_split(problem.n_items, 0.2, seed)
splits = kfold(fit_items, 4, seed + 1, 2500)
base = frozenset({"exposure_overlap"})
s0, p0, _ = cross_validated(problem, base, splits, None)
for extra in ("integration_offset", "detection_threshold"):
    model = base | {extra}
    s, fits, per = cross_validated(problem, model, splits, p0)
    print(extra, round(s, 4))
    for k, (train, val) in enumerate(splits):
        f = fits[k]
        tr = np.sqrt(np.mean(problem.residual(f, train) ** 2))
        va = np.mean(np.abs(problem.residual(f, val)))
        print(
            f"  fold {k} train rmse {tr:.3f} val mae {va:.3f}",
            {a: float(f"{b:.4g}") for a, b in f.params.items()},
            f.extra,
        )
