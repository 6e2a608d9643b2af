"""Per camsim blinding case of batch folders: whether colour_correction was offered (``selection.not_offered``),
withdrawn, and the effects named. Usage: ``python docs/bench/session70/offered.py OUTDIR...``"""

from __future__ import annotations

import json
import sys
from pathlib import Path

for out in sys.argv[1:]:
    for report in sorted(Path(out).glob("bt_*/camsim0/blinding_*/out/report.json")):
        if "_seed" in report.parts[-3]:  # the file's fixed-seed tests, not the master seed's draw
            continue
        r = json.loads(report.read_text())
        seed, case = report.parts[-5][3:], report.parts[-3]
        offered = "not offered" if "colour_correction" in r["selection"]["not_offered"] else "offered"
        withdrawn = [w["effect"] for w in r["selection"]["withdrawn"]]
        print(
            f"{Path(out).name} {seed} {case}: colour_correction {offered}; withdrawn {withdrawn}; named {r['extended']['effects']}"
        )
