"""Session 49's lead (b), measured before building it: what held-out error a drawn second camera would get if its
held-out rows were predicted as their expected count over the detection thresholds the fit rows allow, instead of
at one fitted threshold.

For STRIPES_SEED and a frame rule: ``lerobot-phantom-calibrate`` on ``test_stripes.py``'s table (the test's flags),
then a profile over the threshold of the model ``written effects + integration_offset + detection_threshold``
(read noise kept if written): at each threshold of a log grid every other parameter is refitted on the fit rows
(least squares from the written fit and from the neighbouring grid point). The thresholds the fit rows allow are
those whose profile error passes a 90% likelihood-ratio bar with Gaussian errors (``n log(SSE/SSE_min) <= 2.706``,
n fit rows). Printed: the written model's held-out RMSE, the profile minimum's, the 90% set's range of thresholds,
and the held-out RMSE of the expected count (each held-out row's prediction averaged over the grid, weighted by the
profile likelihood ``(SSE/SSE_min)^(-n/2)``; the grid is uniform in log threshold, so the prior is too), with the
worst held-out row's measured rows, written prediction and its range over the 90% set. Nothing here changes the
package; held-out rows inform nothing but their own score.

Usage: ``HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session51/threshold_profile_probe.py SEED lit|interior``
"""

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

CHI2_1_90 = 2.706
GRID = np.geomspace(1e-7, 3e-4, 61)


def main() -> None:
    seed, frames = int(sys.argv[1]), sys.argv[2]
    style = "exposure" if frames == "interior" else "exposure_us"
    with tempfile.TemporaryDirectory() as root:
        camera, report = ts.calibrate_drawn_camera(
            Path(root), seed, frames, style, calibration_seed=seed % 1000
        )
        problem = StripeProblem(
            Path(root) / "second_camera.csv",
            image_height=camera["height"],
            exposure_unit_s=1e-6 if style == "exposure" else None,
        )
    extended = report["extended"]
    rule = extended["derived"]["frames_averaged"]
    written = Fit(frozenset(extended["effects"]), extended["params"], {"frames": rule})
    fit_items, held = seeded_split(problem.n_items, 0.2, seed % 1000)
    if "phase_drift" in written.effects:
        print(f"{seed} {frames}: written model has phase_drift, not profiled")
        return
    effects = written.effects | {"exposure_overlap", "integration_offset", "detection_threshold"}
    specs = [p for p in problem.param_specs(effects) if p.name != "threshold_s"]
    target = torch.as_tensor(problem.rows[fit_items])
    held_target = problem.rows[held]

    def fitted_at(threshold: float, starts: list[dict]) -> tuple[float, dict]:
        fixed = torch.tensor(threshold, dtype=torch.float64)
        params = fit_least_squares(
            specs,
            lambda p: problem.predict(effects, {**p, "threshold_s": fixed}, fit_items, rule) - target,
            warm=starts[0],
            starts=starts[1:],
        )
        params["threshold_s"] = threshold
        with torch.no_grad():
            values = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
            sse = float(torch.sum((problem.predict(effects, values, fit_items, rule) - target) ** 2))
        return sse, params

    base = dict(written.params)
    sse, preds, fitted = [], [], []
    for k, threshold in enumerate(GRID):
        error, params = fitted_at(float(threshold), [base] + ([fitted[k - 1]] if k else []))
        sse.append(error)
        fitted.append(params)
        preds.append(problem.predict_fit(Fit(effects, params, {"frames": rule}), held))
    # a second sweep downwards: a fit that crossed a stripe-count regime on the way up is started from above too
    for k in range(len(GRID) - 2, -1, -1):
        error, params = fitted_at(float(GRID[k]), [fitted[k + 1]])
        if error < sse[k]:
            sse[k], fitted[k] = error, params
            preds[k] = problem.predict_fit(Fit(effects, params, {"frames": rule}), held)
    sse, preds = np.array(sse), np.array(preds)
    n = len(fit_items)
    floor = max(sse.min(), 1e-12)
    statistic = n * np.log(np.maximum(sse, floor) / floor)
    allowed = statistic <= CHI2_1_90
    weight = np.exp(-0.5 * (statistic - statistic.min()))
    expected = (weight[:, None] * preds).sum(0) / weight.sum()
    best = int(np.argmin(sse))

    def rmse(prediction: np.ndarray) -> float:
        return float(np.sqrt(np.mean((prediction - held_target) ** 2)))

    point = problem.predict_fit(written, held)
    worst = int(np.argmax(np.abs(point - held_target)))
    truth = camera["threshold_grey"] / camera["gain"]
    print(
        f"{seed} {frames:8s} written {'+'.join(sorted(written.effects))} held-out {rmse(point):7.2f} | profile "
        f"{'+'.join(sorted(effects))}: minimum at {GRID[best] * 1e6:.3g} us held-out {rmse(preds[best]):7.2f}, "
        f"90% set {GRID[allowed].min() * 1e6:.3g}-{GRID[allowed].max() * 1e6:.3g} us "
        f"({allowed.sum()} of {len(GRID)} grid points), camera's {truth * 1e6:.3g} us | expected count held-out "
        f"{rmse(expected):7.2f} | worst row {problem.item_label(int(held[worst]))}: measured "
        f"{held_target[worst]:.1f} written {point[worst]:.1f} expected {expected[worst]:.1f} "
        f"range over the set {preds[allowed, worst].min():.1f}-{preds[allowed, worst].max():.1f}"
    )


if __name__ == "__main__":
    main()
