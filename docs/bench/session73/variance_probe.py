"""Render camsim cases on master seeds and calibrate them exactly as session 64's ``run_camsim_case.py`` does,
keeping every variance-by-position test's input (the residuals' sensor-noise sample, their positions, the caller)
as one pickle per case for ``variance_statistic.py``. The package's own test still runs; nothing it reports changes.
Usage: ``PYTHONPATH=.:tests/calibration:tests:docs/bench python docs/bench/session73/variance_probe.py OUTDIR
CASE[,CASE...] SEED...`` (OUTDIR/bt_SEED/camsim0/CASE must not exist)."""

import inspect
import pickle
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session64"))
from camsim_case_cameras import case_draws
from run_camsim_case import render_and_calibrate

from lerobot_phantom.calibration import structure

calls: list[dict] = []
original = structure.variance_tests


def recording(sample, base_mse, rng, family=None):
    calls.append(
        {
            "caller": [frame.function for frame in inspect.stack()[1:6]],
            "noise": sample.noise,
            "position": sample.noise_position,
            "base_mse": base_mse,
            "family": family,
        }
    )
    return original(sample, base_mse, rng, family=family)


def main() -> None:
    out, names, seeds = Path(sys.argv[1]), sys.argv[2].split(","), [int(s) for s in sys.argv[3:]]
    structure.variance_tests = recording
    for name in names:
        for master, _sim, case, seed, rng, camera in case_draws(name, seeds):
            calls.clear()
            render_and_calibrate(out, name, master, case, seed, rng, camera)
            with open(out / f"{master}_{name}.pkl", "wb") as f:
                pickle.dump(list(calls), f)


if __name__ == "__main__":
    main()
