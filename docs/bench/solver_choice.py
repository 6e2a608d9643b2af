"""scipy's trust-region step, ``lsmr`` or ``exact``: fits, function evaluations and CPU per parameter count.

Calibrates each shared input once per solver, in this one process, one after another; every least-squares call
in ``calibration/core.py`` is made with the solver under test (two parameters or fewer: always exact, as in
``fit_least_squares``). Prints, per input and solver, the total user CPU, the model written and its held-out
RMSE, and per number of fitted parameters the fits made, their mean evaluations and their CPU; then the largest
relative difference between the two solvers' fitted parameters.

    OMP_NUM_THREADS=1 python docs/bench/solver_choice.py MEASURED_DIR SCRATCH_DIR [INPUT ...]

(MEASURED_DIR: ``../shared/measured``, third-party data not in this repository; SCRATCH_DIR must not exist;
INPUT: keys of ``INPUTS``, all of them when none is given. Session 23 added the laser captures.)
"""

from __future__ import annotations

import collections
import sys
import time
from pathlib import Path

from lerobot_phantom.calibration import core
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

INPUTS = {
    "stop sign (colour triples)": dict(
        attack="light_projection", measured="projection/slap_stop_sign_triples.csv"
    ),
    "Logitech stripe table": dict(
        attack="laser_color_strip",
        measured="rolling_shutter/logitech_stripe_rows.csv",
        image_height=720,
        exposure_unit_s=1e-4,
    ),
    "laser captures": dict(attack="laser_blinding", measured="blinding"),
}
SOLVERS = ("lsmr", "exact")


def main(measured: Path, scratch: Path, names: list[str]) -> None:
    unknown = sorted(set(names) - set(INPUTS))
    if unknown:
        raise SystemExit(f"unknown inputs {unknown}; valid: {', '.join(INPUTS)}")
    scratch.mkdir(parents=True)
    scipy_least_squares = core.least_squares
    for name in names or INPUTS:
        options = INPUTS[name]
        fitted = {}
        for solver in SOLVERS:
            calls: list[tuple[int, int, float]] = []

            def least_squares(fun, x0, solver=solver, calls=calls, **kwargs):
                kwargs["tr_solver"] = solver if len(x0) > 2 else "exact"
                start = time.process_time()
                result = scipy_least_squares(fun, x0, **kwargs)
                calls.append((len(x0), result.nfev, time.process_time() - start))
                return result

            core.least_squares = least_squares
            start = time.process_time()
            config = CalibrateConfig(
                **{**options, "measured": str(measured / options["measured"])},
                out=str(scratch / f"{len(list(scratch.iterdir()))}"),
            )
            report = calibrate(config)
            total = time.process_time() - start
            core.least_squares = scipy_least_squares
            fitted[solver] = report["extended"]["params"]
            print(
                f"{name}, {solver}: {total:.1f} s CPU; written {report['extended']['effects']}, "
                f"held-out {report['extended']['heldout_rmse']:.4f}"
            )
            per_count = collections.defaultdict(list)
            for count, nfev, cpu in calls:
                per_count[count].append((nfev, cpu))
            for count, runs in sorted(per_count.items()):
                print(
                    f"  {count:2d} parameters: {len(runs):3d} fits, mean {sum(r[0] for r in runs) / len(runs):5.1f} "
                    f"evaluations, {sum(r[1] for r in runs):5.1f} s CPU"
                )
        differences = [abs(fitted["exact"][k] - v) / max(abs(v), 1e-12) for k, v in fitted["lsmr"].items()]
        print(
            f"{name}: largest relative difference over {len(differences)} fitted parameters "
            f"{max(differences, default=0.0):.2e}",
            flush=True,
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3:])
