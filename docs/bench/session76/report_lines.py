"""One line per calibration report: its input, the written model's effects, held-out RMSE (base -> written), and the
light projection parameters with their 90% intervals. Usage: ``python docs/bench/session76/report_lines.py
LABEL=REPORT_JSON...``."""

import json
import sys
from pathlib import Path

for argument in sys.argv[1:]:
    label, path = argument.split("=", 1)
    report = json.loads(Path(path).read_text())
    extended = report["extended"]
    shown = ", ".join(
        f"{k} {extended['params'][k]:.3f} [{extended['param_intervals'][k]['low']:.3f}, "
        f"{extended['param_intervals'][k]['high']:.3f}]"
        for k in ("projector_gamma", "reflectance_floor", "shoulder_exponent", "gamma", "white")
        if k in extended["params"]
    )
    print(
        f"{label}: {extended['effects']}; held-out {report['base']['heldout_rmse']:.2f} -> "
        f"{extended['heldout_rmse']:.2f}; {shown}; withdrawn "
        f"{[w['effect'] for w in report['selection']['withdrawn']]}"
    )
