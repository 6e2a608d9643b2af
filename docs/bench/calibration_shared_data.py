"""The README's Real-Sim-Real table: ``lerobot-phantom-calibrate`` on the shared measured data, one run per input.

Usage: ``python docs/bench/calibration_shared_data.py MEASURED_DIR OUT_JSON [--note TEXT]``
(MEASURED_DIR: ``../shared/measured``, third-party data that is not in this repository). Each input is calibrated
by the console script in a subprocess (seed 0, 20% held out, the CLI's defaults) into a scratch directory; the
JSON keeps the fitted numbers (with their intervals since session 27) and scores of each ``report.json`` and the
run's user CPU seconds (the children's ``getrusage``, as ``/usr/bin/time`` reports them). Refuses to overwrite
OUT_JSON.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import tempfile
from pathlib import Path

# name: (attack, input under MEASURED_DIR, further flags)
RUNS = {
    "laser_color_strip": (
        "laser_color_strip",
        "rolling_shutter/logitech_stripe_rows.csv",
        ["--image-height", "720", "--exposure-unit-s", "1e-4"],
    ),
    "light_projection_stop_sign": ("light_projection", "projection/slap_stop_sign_triples.csv", []),
    "light_projection_bottle": ("light_projection", "projection/slap_bottle_triples.csv", []),
    "laser_blinding": ("laser_blinding", "blinding", []),
}


def summarise(report: dict) -> dict:
    return {
        "base_heldout_rmse": report["base"]["heldout_rmse_interval"],
        "extended_heldout_rmse": report["extended"]["heldout_rmse_interval"],
        "rmse_ratio": report["gain"]["rmse_ratio_interval"],
        "units": report["units"],
        "named_causes": sorted(report["extended"]["effects"]),
        "not_identified": sorted(r["effect"] for r in report["identification"] if not r["identified"]),
        "extended_params": report["extended"]["params"],
        "extended_param_intervals": report["extended"]["param_intervals"],
        "derived": report["extended"].get("derived", {}),
        "unexplained_structure": report["unexplained_structure"]["summary"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("measured", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--note", default="", help="where and how the run was made (machine load, commit)")
    args = parser.parse_args()
    if args.out.exists():
        raise SystemExit(f"{args.out} exists: pass a new path (this script never overwrites a result)")
    if not args.measured.is_dir():
        raise SystemExit(f"{args.measured}: not a directory (expected ../shared/measured)")
    runs = {}
    with tempfile.TemporaryDirectory() as scratch:
        for name, (attack, relative, flags) in RUNS.items():
            out = Path(scratch) / name
            before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
            command = [
                "lerobot-phantom-calibrate",
                "--attack",
                attack,
                "--measured",
                str(args.measured / relative),
                *flags,
                "--out",
                str(out),
            ]
            subprocess.run(command, check=True, capture_output=True)
            cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
            report = json.loads((out / "report.json").read_text())
            runs[name] = {
                "measured": f"{relative} {' '.join(flags)}".strip(),
                **summarise(report),
                "cpu_user_s": round(cpu, 2),
            }
            print(
                f"{name}: base {runs[name]['base_heldout_rmse']['estimate']:.3g}, written "
                f"{runs[name]['extended_heldout_rmse']['estimate']:.3g}, named {runs[name]['named_causes']}, "
                f"not identified {runs[name]['not_identified']}, {cpu:.0f} s CPU",
                flush=True,
            )
    args.out.write_text(
        json.dumps(
            {
                "what": "lerobot-phantom-calibrate on the shared measured data (../shared/measured, not in this "
                "repository): the figures of the README's Real-Sim-Real table; fitted numbers and scores only",
                "script": "docs/bench/calibration_shared_data.py",
                "note": args.note,
                "seed": 0,
                "heldout_share": 0.2,
                "runs": runs,
            },
            indent=1,
        )
        + "\n"
    )


if __name__ == "__main__":
    main()
