"""Session 48 scratch probe, run from a checkout's root with that checkout on PYTHONPATH (outputs beside it name
the commit). In-sample and held-out RMSE of the offset, threshold and threshold+noise models on a drawn camera: the fit's own search, a fit started at the camera's parameters, and those parameters themselves: ``python truth_probe.py SEED [lit|interior]``"""

# ruff: noqa: E402  (the drawn seed is set in the environment before the test module is imported)

"""In-sample and held-out error of models on one drawn second camera: the selected one vs truth-started fits."""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

os.environ["STRIPES_SEED"] = sys.argv[1]
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")
import test_stripes as ts

from lerobot_phantom.calibration.core import Fit, fit_least_squares, seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

frames = sys.argv[2] if len(sys.argv) > 2 else "interior"
style = "exposure" if frames == "interior" else "exposure_us"
with tempfile.TemporaryDirectory() as root:
    table = Path(root) / "t.csv"
    camera = ts.drawn_camera_table(table, ts.SEED, frames, style)
    problem = StripeProblem(
        table, image_height=camera["height"], exposure_unit_s=1e-6 if style == "exposure" else None
    )
fit_items, held = seeded_split(problem.n_items, 0.2, ts.SEED % 1000)
print(ts.camera_summary(camera))
truth = {
    "row_time_s": camera["row_time"],
    "integration_offset_s": camera["offset"] + 2 * camera["spread"] * camera["row_time"],
    "threshold_s": camera["threshold_grey"] / camera["gain"],
    "noise_s": camera["read_noise"] / camera["gain"],
}


def show(name, fit):
    r_fit = problem.predict_fit(fit, fit_items) - problem.rows[fit_items]
    r_held = problem.predict_fit(fit, held) - problem.rows[held]
    print(
        f"{name:40s} fit rmse {np.sqrt(np.mean(r_fit**2)):7.2f} mae {np.mean(np.abs(r_fit)):6.2f} | held rmse {np.sqrt(np.mean(r_held**2)):7.2f}  {dict((k, float(f'{v:.4g}')) for k, v in fit.params.items())}"
    )
    return r_held


for effects in [
    {"exposure_overlap", "integration_offset"},
    {"exposure_overlap", "integration_offset", "detection_threshold"},
    {"exposure_overlap", "integration_offset", "detection_threshold", "detection_noise"},
]:
    effects = frozenset(effects)
    fit = problem.fit(effects, fit_items)
    show("+".join(sorted(effects)) + " search", fit)
    target = torch.as_tensor(problem.rows[fit_items])
    params = fit_least_squares(
        problem.param_specs(effects),
        lambda p, effects=effects, target=target: problem.predict(effects, p, fit_items, frames) - target,
        warm={k: v for k, v in truth.items() if k in {s.name for s in problem.param_specs(effects)}},
    )
    r = show("+".join(sorted(effects)) + " truth-started", Fit(effects, params, {"frames": frames}))
    tf = Fit(effects, {k: v for k, v in truth.items() if k in params}, {"frames": frames})
    r = show("  truth itself", tf)
print("held-out rows:", [problem.item_label(i) for i in held])
