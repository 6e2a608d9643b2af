"""One stripe table calibrated on several held-out splits: how the written model and its held-out error depend on
which rows are held out.

Usage: ``python docs/bench/stripe_table_seeds.py TABLE OUT_JSON --seeds 0-9 [calibrate flags] [--note TEXT]``.
Each split seed runs ``lerobot-phantom-calibrate`` in a subprocess (the CLI's defaults otherwise) into a scratch
directory; the JSON keeps ``calibration_shared_data.summarise`` of each ``report.json`` (fitted numbers, scores,
named causes, the structure summary) and its user CPU seconds, never the table's values. Refuses to overwrite
OUT_JSON. Made for tables that are not in this repository (the Axis camera table of "They See Me Rollin'",
GPL-3.0: read it by path).
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from calibration_shared_data import summarise


def seed_range(text: str) -> list[int]:
    low, _, high = text.partition("-")
    return list(range(int(low), int(high or low) + 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--seeds", type=seed_range, default=seed_range("0-9"), help="e.g. 0-9")
    parser.add_argument("--note", default="", help="where and how the run was made (machine load, commit)")
    args, flags = parser.parse_known_args()
    if args.out.exists():
        raise SystemExit(f"{args.out} exists: pass a new path (this script never overwrites a result)")
    runs = {}
    with tempfile.TemporaryDirectory() as scratch:
        for seed in args.seeds:
            out = Path(scratch) / str(seed)
            before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
            command = [
                "lerobot-phantom-calibrate",
                "--attack",
                "laser_color_strip",
                "--measured",
                str(args.table),
            ]
            subprocess.run(
                [*command, *flags, "--seed", str(seed), "--out", str(out)], check=True, capture_output=True
            )
            cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
            runs[seed] = {
                **summarise(json.loads((out / "report.json").read_text())),
                "cpu_user_s": round(cpu, 2),
            }
            run = runs[seed]
            print(
                f"seed {seed}: base {run['base_heldout_rmse']['estimate']:.3g}, written "
                f"{run['extended_heldout_rmse']['estimate']:.3g}, named {run['named_causes']}, not identified "
                f"{run['not_identified']}, {cpu:.0f} s CPU; {run['unexplained_structure'][:160]}",
                flush=True,
            )
    written = np.array([r["extended_heldout_rmse"]["estimate"] for r in runs.values()])
    summary = {
        "seeds": len(written),
        "written_heldout_rmse_mean": float(written.mean()),
        "written_heldout_rmse_median": float(np.median(written)),
        "written_heldout_rmse_max": float(written.max()),
        "named_phase_drift": sum("phase_drift" in r["named_causes"] for r in runs.values()),
        "named_drift_from_entry": sum("drift_from_entry" in r["named_causes"] for r in runs.values()),
        "splits_at_most_30_rows": int((written <= 30.0).sum()),
    }
    print(json.dumps(summary))
    args.out.write_text(
        json.dumps(
            {
                "what": "lerobot-phantom-calibrate on one stripe table (not in this repository) over held-out split "
                "seeds; fitted numbers and scores only",
                "script": "docs/bench/stripe_table_seeds.py",
                "table": args.table.name,
                "flags": flags,
                "note": args.note,
                "summary": summary,
                "runs": runs,
            },
            indent=1,
        )
        + "\n"
    )


if __name__ == "__main__":
    main()
