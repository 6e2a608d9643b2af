"""The drift tests' tables (tests/calibration/test_stripes.py, ``drift_reports``) on several STRIPES_SEEDs: per seed and
start (placement, entry), what the calibration names, what it withdrew and why, the drift start's gain beside the
exposure overlap and drift where a step took them together (``gain_in_group``), and the held-out rows against the
locked model's, as the drift test scores them.

usage: [DRIFT_STARTS=placement] PYTHONPATH=TREE:tests/calibration:tests python docs/bench/session100/drift_groups.py OUT
SEED... (DRIFT_STARTS: the starts to run, comma-separated; default placement,entry)
"""

import json
import os
import sys
from pathlib import Path

os.environ.setdefault("STRIPES_SEED", "0")  # test_stripes reads it at import; each seed is passed below
os.environ.setdefault("HF_HUB_OFFLINE", "1")

import numpy as np
import test_stripes as ts

import lerobot_phantom
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.stripes import DRIFT_EFFECTS, StripeProblem


def calibrate_drift_table(where: Path, seed: int, start: str) -> tuple[dict, dict, np.ndarray, Path]:
    """(report.json, camera, drifts, table) of the drift test's calibration of ``seed``'s table from ``start``,
    written under ``where`` (split seed ``seed % 1000``, 10 bootstrap draws, as ``drift_reports``)."""
    rng, camera, drifts = ts.drifting_draw(seed, drifting=True)
    where.mkdir(parents=True, exist_ok=True)
    table = where / "drifting.csv"
    ts.drifting_table(table, camera, rng, drifts, start_at=start)
    config = CalibrateConfig(
        attack="laser_color_strip",
        measured=str(table),
        out=str(where / "out"),
        image_height=camera["height"],
        seed=seed % 1000,
        bootstrap=10,
    )
    return calibrate(config), camera, drifts, table


def main(out: Path, seeds: list[int]) -> None:
    print("# package:", Path(lerobot_phantom.__file__).resolve().parent, flush=True)
    for seed in seeds:
        for start in os.environ.get("DRIFT_STARTS", "placement,entry").split(","):
            where = out / f"{seed}_{start}"
            report, camera, drifts, table = calibrate_drift_table(where, seed, start)
            problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
            fit_items, heldout = seeded_split(problem.n_items, 0.2, seed % 1000)
            locked = problem.fit(frozenset(report["extended"]["effects"]) - set(DRIFT_EFFECTS), fit_items)
            named = sorted(f["effect"] for f in report["findings"])
            withdrawn = [w["effect"] for w in report["selection"]["withdrawn"]]
            gains = {
                r["effect"]: r["gain_in_group"] for r in report["identification"] if "gain_in_group" in r
            }
            earlier = report["selection"].get("earlier_passes") or []
            gain_text = "; ".join(
                f"{e} {g['estimate']:.3f} [{g['low']:.3f}, {g['high']:.3f}] beside {g['others']}"
                for e, g in gains.items()
            )
            withdrawn_text = "; ".join(
                f"{w['effect']}: {w['reasons'][0][:150]}" for w in report["selection"]["withdrawn"]
            )
            print(
                f"{seed} {start:9s} drifts {np.round(drifts, 3).tolist()} named {named} withdrawn {withdrawn} "
                f"held-out {report['extended']['heldout_rmse']:.2f} locked {problem.rmse(locked, heldout):.2f}"
                + (f"\n    gain in group: {gain_text}" if gain_text else "")
                + (f"\n    withdrawn: {withdrawn_text}" if withdrawn_text else "")
                + (f"\n    earlier passes: {len(earlier)}" if earlier else ""),
                flush=True,
            )
            (where / "report_summary.json").write_text(json.dumps({"named": named, "withdrawn": withdrawn}))


if __name__ == "__main__":
    main(Path(sys.argv[1]), [int(s) for s in sys.argv[2:]])
