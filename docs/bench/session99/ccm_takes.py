"""Each draw's camsim matrix as the fit's takes would write it (column j's off-diagonals, averaged: the light of raw
channel j taken out of the other channels), beside the takes the calibrations in OUTDIRs wrote, for one case.
Usage: ``CAMSIM_CCM=1 CAMSIM_SEED=1 PYTHONPATH=.:tests/calibration:tests python docs/bench/session99/ccm_takes.py
CASE OUTDIR... `` (camsim_core_batch.sh outputs: OUTDIR/bt_SEED/camsim0/CASE/out/report.json)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

CHANNELS = ("red", "green", "blue")


def main() -> None:
    name, outs = sys.argv[1], [Path(p) for p in sys.argv[2:]]
    seeds = sorted({int(p.name[3:]) for out in outs for p in out.glob("bt_*")})
    for master, _sim, _case, seed, _rng, camera in case_draws(name, seeds):
        matrix = np.reshape(camera.ccm, (3, 3))
        takes = [-float(np.mean([matrix[i, j] for i in range(3) if i != j])) for j in range(3)]
        print(f"{master} {name} (case seed {seed}): camsim's takes {np.round(takes, 3).tolist()}")
        for out in outs:
            report = out / f"bt_{master}" / "camsim0" / name / "out" / "report.json"
            if report.exists():
                params = json.loads(report.read_text())["extended"]["params"]
                fitted = [round(params[f"ccm_{c}"], 3) for c in CHANNELS] if "ccm_red" in params else None
                off = (
                    f", mean |fitted - camsim's| {np.mean(np.abs(np.subtract(fitted, takes))):.3f}"
                    if fitted
                    else ""
                )
                print(f"  {out.name}: {fitted if fitted else 'no matrix named'}{off}")


if __name__ == "__main__":
    main()
