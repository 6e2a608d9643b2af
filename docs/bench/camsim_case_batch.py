"""One camsim case calibrated on several master seeds: what it names, against what was planted.

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/camsim_case_batch.py CASE SEED...`` from the repository root
(``CAMSIM_SEED`` only has to exist for the import; each seed replaces it). Renders the case exactly as
``tests/calibration/test_independent_sim.py`` does for that master seed, runs the calibration CLI on it and prints
one line per seed: the planted effects left unnamed, the named causes (the test's own rule), the camera's tone curve
and the held-out RMSE of the base and of the written model.
"""

from __future__ import annotations

import importlib
import os
import sys
import tempfile
from collections.abc import Iterator
from types import ModuleType

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports


def cases_per_master_seed(name: str, seeds: list[str]) -> Iterator[tuple[str, ModuleType, object]]:
    """(master seed, the test module drawn for it, its case ``name``) per seed, as the test draws them."""
    for seed in seeds:
        os.environ["CAMSIM_SEED"] = seed
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        yield seed, sim, sim.CASE_BY_NAME[name]


def run_on_master_seed(name: str, seed: str) -> tuple[ModuleType, dict]:
    """The test module drawn for master ``seed`` and its ``run_case(name)`` result (report, case seed, camera)."""
    ((_, sim, _case),) = cases_per_master_seed(name, [seed])
    with tempfile.TemporaryDirectory() as root:
        return sim, sim.run_case(name, root)


def main() -> None:
    name, seeds = sys.argv[1], sys.argv[2:]
    for seed, sim, case in cases_per_master_seed(name, seeds):
        with tempfile.TemporaryDirectory() as root:
            result = sim.run_case(name, root)
        report, named = result["report"], sim.named_causes(result["report"])
        print(
            f"{name} {seed} planted-missing {sorted(case.planted - named)} named {sorted(named)} "
            f"tone {result['camera'].tone} heldout {report['base']['heldout_rmse']:.2f} -> "
            f"{report['extended']['heldout_rmse']:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
