"""Per camsim report under the given batch outputs: the effects rule 2 withdrew as redundant (the withdrawal's
reason) and the effects it kept because a bound pins another without them (the note), as report.json states them.

usage: python docs/bench/session101/redundancy_notes.py OUT...
"""

import json
import sys
from pathlib import Path

for root in sys.argv[1:]:
    for path in sorted(Path(root).rglob("out/report.json")):
        report = json.loads(path.read_text())
        lines = [
            f"withdrawn {w['effect']}: {reason}"
            for w in report["selection"]["withdrawn"]
            for reason in w["reasons"]
            if "half the selection margin" in reason
        ]
        lines += [
            f"kept {result['effect']}: {note}"
            for result in report["identification"]
            for note in result.get("notes", [])
            if note.startswith("not shown redundant")
        ]
        for line in lines:
            print(f"{root} {path.parent.parent.name}: {line}")
