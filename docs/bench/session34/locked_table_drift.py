"""Why ``phase_drift`` is kept on one all-locked table of the test simulator: the naming test's null draw for one
``STRIPES_SEED`` (its camera, five locked recordings), the written model's effects fitted on the split's fit rows,
and per fit row its residual with the fitted drifts and with every drift locked, and the drop in squared error over
the model's error (the drift rule's weight; the simulated table has no standard errors).

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session34/locked_table_drift.py SEED EFFECT [EFFECT ...]
[--camera KEY=VALUE ...]``; ``--camera`` overrides a drawn camera property (``read_noise=0``, ``spread=0``,
``rise=1e-9``) after the draw, so the table is rendered from the same random stream with one term removed.
"""

import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch


def main(seed: int, effects: frozenset[str], overrides: dict[str, float], keep_table: Path | None) -> None:
    os.environ["STRIPES_SEED"] = str(seed)  # the test module reads its seed at import
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    from lerobot_phantom.calibration.core import seeded_split
    from lerobot_phantom.calibration.stripes import StripeProblem

    rng = np.random.default_rng([seed, 7])
    camera = test_stripes.draw_camera(rng, "interior")
    unknown = set(overrides) - set(camera)
    if unknown:
        raise SystemExit(f"unknown camera properties {sorted(unknown)}; valid: {', '.join(sorted(camera))}")
    camera |= {k: type(camera[k])(v) for k, v in overrides.items()}
    table = Path(tempfile.mkdtemp()) / "locked.csv"
    test_stripes.drifting_table(table, camera, rng, np.zeros(5))
    if keep_table is not None:
        if keep_table.exists():
            raise SystemExit(f"{keep_table} exists; give a new path")
        shutil.copyfile(table, keep_table)
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    print(test_stripes.camera_summary(camera))
    items, _ = seeded_split(problem.n_items, 0.2, seed % 1000)
    fit = problem.fit(effects, items)
    print({k: float(f"{v:.4g}") for k, v in fit.params.items()}, fit.extra)
    values = {k: torch.tensor(v, dtype=torch.float64) for k, v in fit.params.items()}
    zero = torch.tensor(0.0, dtype=torch.float64)
    with torch.no_grad():
        fitted = problem.predict(effects, values, items, "interior").numpy() - problem.rows[items]
        locked = (
            problem.predict(
                effects, values | dict.fromkeys(problem.drift_names, zero), items, "interior"
            ).numpy()
            - problem.rows[items]
        )
    model_variance = float(np.mean(fitted**2))
    print(f"model error (rows): {np.sqrt(model_variance):.3f}")
    for item, residual, residual_locked in zip(items, fitted, locked, strict=True):
        print(
            f"{problem.drift_names[problem.recording[item]]} duty {100 * problem.duty[item]:g}%: "
            f"residual {residual:+.2f}, locked {residual_locked:+.2f}, "
            f"drop {(residual_locked**2 - residual**2) / model_variance:.2f}"
        )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("seed", type=int)
    parser.add_argument("effects", nargs="+")
    parser.add_argument("--camera", nargs="*", default=[], metavar="KEY=VALUE")
    parser.add_argument("--keep-table", type=Path, help="also write the rendered table here (a new file)")
    args = parser.parse_args()
    malformed = [o for o in args.camera if "=" not in o]
    if malformed:
        parser.error(f"--camera takes KEY=VALUE (e.g. read_noise=0), not {malformed}")
    overrides = {k: float(v) for k, v in (o.split("=", 1) for o in args.camera)}
    main(args.seed, frozenset(args.effects), overrides, args.keep_table)
