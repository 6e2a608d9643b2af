"""Chosen stripe models fitted on a drawn second camera's fit rows (``test_stripes.calibrate_drawn_camera``'s table,
split and frame rules), without selection: each model's fitted parameters, fit error, held-out RMSE and the held-out
rows it errs on by more than 20 rows. Shows what a model could predict that selection did not write. Run from a
checkout, whose package is what is measured:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session41/forced_models.py SEED lit|interior \
        EFFECT[+EFFECT...] ...
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np

seed, frames = int(sys.argv[1]), sys.argv[2]
os.environ["STRIPES_SEED"] = str(seed)  # the test module draws its seed at import
sys.path.insert(0, str(Path("tests/calibration").resolve()))
import test_stripes  # noqa: E402

from lerobot_phantom.calibration.core import seeded_split  # noqa: E402
from lerobot_phantom.calibration.stripes import StripeProblem  # noqa: E402

rng = np.random.default_rng([seed, 2, len(frames)])  # calibrate_drawn_camera's draw
camera = test_stripes.draw_camera(rng, frames)
style, unit = ("exposure_us", None) if frames == "lit" else ("exposure", 1e-6)
with tempfile.TemporaryDirectory() as tmp:
    table = Path(tmp) / "second_camera.csv"
    test_stripes.write_table(table, camera, rng, n_rows=60, frames=60, style=style)
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=unit, frames="auto")
fit_items, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
threshold_us, noise_us = (camera[k] / camera["gain"] * 1e6 for k in ("threshold_grey", "read_noise"))
print(
    f"camera: row time {camera['row_time'] * 1e6:.2f} us, offset {camera['offset'] * 1e6:.2f} us, threshold "
    f"{threshold_us:.2f} us, read noise {noise_us:.2f} us"
)
for model in sys.argv[3:]:
    fit = problem.fit(frozenset(model.split("+")), fit_items)
    fit_error = problem.predict_fit(fit, fit_items) - problem.rows[fit_items]
    error = problem.predict_fit(fit, heldout) - problem.rows[heldout]
    params = ", ".join(f"{k} {v * 1e6:.2f} us" for k, v in fit.params.items())
    print(
        f"{model}: {params}, frames {fit.extra.get('frames')}; fit RMSE {np.sqrt(np.mean(fit_error**2)):.2f}, "
        f"held-out RMSE {np.sqrt(np.mean(error**2)):.2f} rows"
    )
    for item, e in zip(heldout, error, strict=True):
        if abs(e) > 20:
            print(
                f"    held-out row {item}: {problem.frequency_hz[item]:g} Hz, duty {problem.duty[item]:g}, exposure "
                f"{problem.exposure_s[item] * 1e6:g} us, measured {problem.rows[item]:.1f}, error {e:+.1f} rows"
            )
