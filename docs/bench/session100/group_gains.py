"""Per case of camsim batch runs (docs/bench/camsim_core_batch.sh OUTDIR): what is named, what was withdrawn, and
every change of form's gain beside the effects a step took it with (``gain_in_group``, session 100).

usage: python docs/bench/session100/group_gains.py OUTDIR...
"""

import json
import sys
from pathlib import Path

for root in sys.argv[1:]:
    for path in sorted(Path(root).glob("bt_*/camsim0/*/out/report.json")):
        report = json.loads(path.read_text())
        named = sorted(f["effect"] for f in report["findings"])
        withdrawn = [w["effect"] for w in report["selection"]["withdrawn"]]
        gains = "; ".join(
            f"{r['effect']} {g['estimate']:.3f} [{g['low']:.3f}, {g['high']:.3f}] beside {g['others']}"
            for r in report["identification"]
            if (g := r.get("gain_in_group"))
        )
        seed = path.parts[-5].removeprefix("bt_")
        print(
            f"{seed} {path.parts[-3]:36s} named {named} withdrawn {withdrawn}"
            + (f"\n    {gains}" if gains else "")
        )
