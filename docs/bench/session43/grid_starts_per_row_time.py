"""A drawn camera of ``test_the_first_fit_finds_the_stripe_count_regime_of_the_camera`` (its table, all rows): the
first fit's RMSE, parameters and CPU time with 2 (the package's), 3, 4 and 6 grid starts per row time
(``StripeProblem.regime_starts``), against the fit started from the camera's own parameters. Run from a checkout,
whose package and test simulator are what is measured:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session43/grid_starts_per_row_time.py SEED \
        lit|interior
"""

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# the test module reads it at import; this script names its own seed
os.environ.setdefault("STRIPES_SEED", "0")
sys.path.insert(0, str(Path("tests/calibration").resolve()))
import test_stripes

from lerobot_phantom.calibration.stripes import StripeProblem

seed, frames = int(sys.argv[1]), sys.argv[2]
with tempfile.TemporaryDirectory() as tmp:
    table = Path(tmp) / "table.csv"
    camera = test_stripes.drawn_camera_table(table, seed, frames)  # the test's table
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
items = np.arange(problem.n_items)


def rmse(fit) -> float:
    return float(np.sqrt(np.mean(problem.residual(fit, items) ** 2)))


def us(params: dict) -> str:
    return ", ".join(f"{k} {v * 1e6:.2f} us" for k, v in params.items())


truth = test_stripes.truth_started_fit(problem, camera, items, frames)
print(f"from the camera's parameters: {rmse(truth):.3f} rows ({us(truth.params)})")
package_starts = StripeProblem.regime_starts
for per_row_time in (2, 3, 4, 6):
    StripeProblem.regime_starts = staticmethod(
        lambda grid, order, n, per_row_time=per_row_time, **_: package_starts(grid, order, n, per_row_time)
    )
    started = time.process_time()
    fit = problem.fit(truth.effects, items)
    cpu = time.process_time() - started
    print(f"{per_row_time} starts per row time: {rmse(fit):.3f} rows ({us(fit.params)}), CPU {cpu:.1f} s")
