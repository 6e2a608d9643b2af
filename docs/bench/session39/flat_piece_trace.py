"""The drift tests' placement table of one STRIPES_SEED under the stripe model without a threshold: the whole table
fitted with exposure_overlap alone and with integration_offset; then, at fixed row times, that model's error on the
table under the interior and lit frame rules; then the model's prediction for each row of one exposure setting
next to the measured rows. Shows a recording the model lights whole (the rounding of section 3).

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session39/flat_piece_trace.py SEED EXPOSURE_US``
"""

import os
import sys
import tempfile
from pathlib import Path

import numpy as np


def main(seed: int, exposure_us: float) -> None:
    os.environ["STRIPES_SEED"] = str(seed)  # read by the test module at import
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    from lerobot_phantom.calibration.stripes import StripeProblem

    rng, camera, drifts = test_stripes.drifting_draw(seed, drifting=True)
    out = Path(tempfile.mkdtemp())
    table = out / "drifting.csv"
    test_stripes.drifting_table(table, camera, rng, drifts, start_at="placement")
    print(test_stripes.camera_summary(camera), f"drifts {drifts.round(3).tolist()}")
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    items = np.arange(problem.n_items)
    for effects in (("exposure_overlap",), ("exposure_overlap", "integration_offset")):
        fit = problem.fit(frozenset(effects), items)
        error = np.asarray(problem.residual(fit, items))
        shown = {k: round(v * 1e6, 2) for k, v in fit.params.items()}
        print(
            f"{'+'.join(effects)} fitted on every row: {fit.extra.get('frames')} rule, {shown} (us), "
            f"RMSE {np.sqrt(np.mean(error**2)):.2f}, mean absolute error {np.mean(np.abs(error)):.2f} rows"
        )
    alone = frozenset({"exposure_overlap"})
    for row_time in np.array([30.0, 32.0, 34.0, camera["row_time"] * 1e6, 36.0, 38.0, 40.0]) * 1e-6:
        for frames in ("interior", "lit"):
            error = (
                problem.predict(alone, {"row_time_s": row_time}, items, frames=frames).numpy() - problem.rows
            )
            print(
                f"row time {row_time * 1e6:6.2f} us, {frames:8s}: RMSE {np.sqrt(np.mean(error**2)):7.2f}, mean "
                f"absolute error {np.mean(np.abs(error)):7.2f} rows"
            )
    prediction = problem.predict(alone, {"row_time_s": camera["row_time"]}, items, frames="interior").numpy()
    for item in np.flatnonzero(np.isclose(problem.exposure_s, exposure_us * 1e-6)):
        print(
            f"exposure {exposure_us:g} us, duty {problem.duty[item] * 100:4.1f}%: measured {problem.rows[item]:7.2f}, "
            f"exposure_overlap alone at the true row time {prediction[item]:7.2f} rows"
        )


if __name__ == "__main__":
    main(int(sys.argv[1]), float(sys.argv[2]))
