"""One camsim ``projection_crosstalk`` draw: effect sets scored as selection scores them (the 4 inner folds of the
fit pairs, from the defaults), with the members a fold fit pins at a bound, and fitted on all fit pairs: fit and
held-out RMSE (grey levels), and the reflectance floor and the shoulder's knee exponent. Usage:
``CAMSIM_SEED=1 PYTHONPATH=.:tests/calibration:tests python docs/bench/session97/crosstalk_structures.py CASE_SEED
SET...`` (a set: effect names joined by ``+``; CAMSIM_SEED only lets the test module import: the case seed is
given). Since session 98 it runs ``session98/structures.py``, the same for any case, with this case (which prints a
fitted gamma too)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session98"))
import structures


def main() -> None:
    sys.argv[1:1] = ["projection_crosstalk"]
    structures.main()


if __name__ == "__main__":
    main()
