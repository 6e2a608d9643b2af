"""Every group of effects a selection step took at once in the report.json files under the given directories (camsim
batch runs of earlier sessions), and per member the point ratio of the step's score of the group without it to the
group's score (from the step's ``tried`` and the completing step; report.json keeps no per-item terms of the tried
groups, so no interval), with whether the step set the group without it aside. Sorted by ratio.

usage: python docs/bench/session100/group_point_ratios.py DIR...
"""

import json
import sys
from pathlib import Path

rows = []
n_reports = 0
for root in sys.argv[1:]:
    for path in sorted(Path(root).rglob("report.json")):
        steps = json.loads(path.read_text())["selection"]["steps"]
        n_reports += 1
        for k in range(len(steps) - 1):
            if not steps[k]["tried"]:
                continue
            # the steps inside a group have no tried groups of their own; the group ends at the next step that has
            j = k + 1
            while j < len(steps) - 1 and not steps[j]["tried"]:
                j += 1
            if j == k + 1:
                continue
            group = set(steps[j]["effects"]) - set(steps[k]["effects"])
            scores = {frozenset(label.split("+")): v for label, v in steps[k]["tried"].items()}
            aside = {frozenset(label.split("+")) for label in steps[k].get("set_aside", {})}
            for member in sorted(group):
                others = frozenset(group - {member})
                ratio = scores.get(others)
                ratio = None if ratio is None else ratio / steps[j]["validation_error"]
                rows.append((ratio, others in aside, member, "+".join(sorted(group)), str(path.parent)))
print(
    f"{n_reports} reports, {len(rows)} group members (ratio '-': the group without it is no model of its own)"
)
for ratio, aside, member, group, where in sorted(rows, key=lambda r: (r[0] is None, r[0] or 0.0)):
    shown = "-" if ratio is None else f"{ratio:.3f}"
    print(f"{shown:>7} {'aside' if aside else '     '} {member:26s} {group:55s} {where}")
