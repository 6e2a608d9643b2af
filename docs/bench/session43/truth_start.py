"""A drawn second camera of ``test_stripes`` (``calibrate_drawn_camera``'s table, split and frame rules): each model
fitted on the fit rows by the library's own search, then scored at the camera's true parameters (under the camera's
frame rule) and fitted from them alone (one local least-squares descent, ``StripeProblem.fit_from``), each with its
fit error (what selection sees) and held-out RMSE. Tells a search that misses a better basin from a basin the fit
rows prefer. Run from a checkout, whose package is what is measured:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session43/truth_start.py SEED lit|interior \
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

from lerobot_phantom.calibration.core import Fit, seeded_split  # noqa: E402
from lerobot_phantom.calibration.stripes import StripeProblem  # noqa: E402

style, unit = ("exposure_us", None) if frames == "lit" else ("exposure", 1e-6)
with tempfile.TemporaryDirectory() as tmp:
    table = Path(tmp) / "second_camera.csv"
    camera = test_stripes.drawn_camera_table(table, seed, frames, style)  # calibrate_drawn_camera's table
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=unit, frames="auto")
fit_items, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
truth = {
    "row_time_s": camera["row_time"],
    # blooming counted in the offset, as test_stripes.truth_started_fit does: both widen every stripe alike
    "integration_offset_s": camera["offset"] + 2 * camera["spread"] * camera["row_time"],
    "threshold_s": camera["threshold_grey"] / camera["gain"],
    "noise_s": camera["read_noise"] / camera["gain"],
}
print(
    "camera: "
    + ", ".join(f"{k} {v * 1e6:.2f} us" for k, v in truth.items())
    + f" (offset {camera['offset'] * 1e6:.2f} us + blooming {camera['spread']} rows), frames {frames}"
)


def describe(label: str, fit: Fit) -> None:
    fit_error = problem.predict_fit(fit, fit_items) - problem.rows[fit_items]
    error = problem.predict_fit(fit, heldout) - problem.rows[heldout]
    params = ", ".join(f"{k} {v * 1e6:.2f} us" for k, v in fit.params.items())
    print(
        f"  {label}: {params}, frames {fit.extra.get('frames')}; fit SSE {np.sum(fit_error**2):.0f} "
        f"(RMSE {np.sqrt(np.mean(fit_error**2)):.2f}), held-out RMSE {np.sqrt(np.mean(error**2)):.2f} rows"
    )


for model in sys.argv[3:]:
    effects = frozenset(model.split("+"))
    print(model)
    describe("searched", problem.fit(effects, fit_items))
    specs = problem.param_specs(effects)
    at_truth = {spec.name: truth[spec.name] for spec in specs}
    describe("at the truth", Fit(effects, at_truth, {"frames": frames}))
    _, descended = problem.fit_from(effects, specs, fit_items, frames, at_truth)
    describe("descent from the truth", Fit(effects, descended, {"frames": frames}))
