"""The camsim reports under the given batch outputs whose passes record, in their last step, a selected effect
without which a bound pins another (``without_pinned``), with those pins; and the count of such reports.

usage: python docs/bench/session101/pinned_without.py OUT...
"""

import json
import sys
from pathlib import Path

for root in sys.argv[1:]:
    paths = sorted(Path(root).rglob("out/report.json"))
    found = 0
    for path in paths:
        selection = json.loads(path.read_text())["selection"]
        passes = [selection["steps"]] + [p["steps"] for p in selection.get("earlier_passes", [])]
        pins = [steps[-1]["without_pinned"] for steps in passes if steps and steps[-1].get("without_pinned")]
        if pins:
            found += 1
            print(f"  {path.parent.parent.name}: {pins}")
    print(f"{root}: {found} of {len(paths)} reports record a pin in a model without an effect")
