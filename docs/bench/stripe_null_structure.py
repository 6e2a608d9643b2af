"""How often does the residual-structure test report structure on a stripe table that has none?

The null table of ``tests/calibration/test_stripes.py::test_fixed_band_keeps_the_base`` (a drawn camera's
frequencies, the paper's fixed band H/3 plus 2 rows of frame noise), N draws. Per draw: a random fifth of the rows
held out, the band fitted as the mean of the rest, and ``structure.residual_structure`` run on the held-out
residual. Only the structure test is exercised, not selection. Prints each variable found significant (draw,
eta squared, its interval's low end, its uncorrected permutation p-value) and the count of draws with structure.

    python docs/bench/stripe_null_structure.py N SCRATCH_DIR
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

# the test module reads STRIPES_SEED on import; each draw below is seeded itself
os.environ.setdefault("STRIPES_SEED", "0")
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "calibration"))

from test_stripes import draw_camera, fixed_band_table

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.stripes import StripeProblem
from lerobot_phantom.calibration.structure import residual_structure


def main(draws: int, scratch: Path) -> None:
    scratch.mkdir(parents=True, exist_ok=True)
    found = 0
    levels = set()
    for draw in range(draws):
        rng = np.random.default_rng([draw, 3])
        camera = draw_camera(rng, "lit")
        table = fixed_band_table(scratch / f"null_{draw}.csv", rng, camera)
        problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
        order = rng.permutation(problem.n_items)
        held_out, fit_items = order[: problem.n_items // 5], order[problem.n_items // 5 :]
        fit = Fit(frozenset(), {"band_rows": float(np.mean(problem.rows[fit_items]))})
        base_mse = float(np.mean(problem.residual(fit, held_out) ** 2))
        structure = residual_structure(problem, fit, held_out, base_mse=base_mse, rng=rng)
        found += structure["structure_remains"]
        for test in structure["tests"]:
            if test["significant"]:
                print(
                    f"draw {draw}: {test['variable']} eta2 {test['value']:.3f}, interval low "
                    f"{test['interval']['low']:.3f}, permutation p {test['p_value']:.4f}",
                    flush=True,
                )
        levels.add(len(camera["frequencies"]))
    print(
        f"structure reported on {found} of {draws} null draws (laser frequencies per table: {sorted(levels)})"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]), Path(sys.argv[2]))
