"""A drawn second camera's stripe table, its rows in order of the pulse's light against the camera's detection
threshold (on-time / threshold, the simulator's own): each row's split (fit or held-out by the calibration's seed), its
window against the laser period (exposure + the camera's offset) and the rows measured. The four drawn cases above
the 30-row bar put their largest held-out error on a pulse at or under the threshold, the table's weakest on three
of them (docs/bench/session48/heldout_rows_probe.py, session102/heldout_rows_*_ef803e9.txt).

Usage: ``PYTHONPATH=. python docs/bench/session102/stripe_regimes.py SEED lit|interior [ROWS]`` (the first ROWS rows,
default 8)."""

import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("STRIPES_SEED", sys.argv[1])  # read when the test module is imported
sys.path.insert(0, "tests/calibration")
sys.path.insert(0, "tests")

import test_stripes as ts

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

seed, frames = int(sys.argv[1]), sys.argv[2]
shown = int(sys.argv[3]) if len(sys.argv) > 3 else 8
style = "exposure" if frames == "interior" else "exposure_us"
with tempfile.TemporaryDirectory() as root:
    table = Path(root) / "second_camera.csv"
    camera = ts.drawn_camera_table(table, seed, frames, style)
    problem = StripeProblem(
        table, image_height=camera["height"], exposure_unit_s=1e-6 if style == "exposure" else None
    )
_, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
threshold = camera["threshold_grey"] / camera["gain"]
on_time = problem.duty / problem.frequency_hz
window_periods = (problem.exposure_s + camera["offset"]) * problem.frequency_hz
print(
    f"STRIPES_SEED={seed} {frames}: height {camera['height']}, threshold {threshold * 1e6:.2f} us of pulse light"
)
for i in sorted(range(problem.n_items), key=lambda k: on_time[k] / threshold)[:shown]:
    print(
        f"  {'held-out' if i in heldout else 'fit     '} {problem.item_label(int(i)):45s} window/period "
        f"{window_periods[i]:6.3f} on/threshold {on_time[i] / threshold:6.2f} rows {problem.rows[i]:7.1f}"
    )
