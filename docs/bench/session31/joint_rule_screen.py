"""Which recorded selection steps take a different group under session 31's joint-group rule (the lowest-scoring
group that earns its step) than under the rule before it (the group furthest under its need), from the scores
``report.json`` already holds (``selection.steps[*].tried`` / ``set_aside``): no fit is repeated, so only the
first step where the rules part is shown; what selection does after it needs a rerun.

Usage: ``PYTHONPATH=. python docs/bench/session31/joint_rule_screen.py REPORT_JSON...``
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from lerobot_phantom.calibration import captures, projection, stripes
from lerobot_phantom.calibration.core import group_needs
from lerobot_phantom.calibration.frame_models import FRAME_PROBLEMS

TABLE_EFFECTS = {
    "light_projection": projection.EFFECTS,
    "laser_color_strip": stripes.EFFECTS,
    "laser_blinding": captures.CAPTURE_EFFECTS,
}


def group_taken(tried: dict, set_aside: dict, current: float, requires: dict, margin: float, rule: str):
    eligible = {frozenset(k.split("+")): v for k, v in tried.items() if k not in set_aside}
    needed = group_needs(requires, eligible, current, margin)
    earned = [g for g in needed if eligible[g] <= needed[g]]
    if earned:
        key = (lambda g: eligible[g] / needed[g]) if rule == "furthest under need" else eligible.get
        return min(earned, key=key)
    single = min((g for g in eligible if len(g) == 1), key=eligible.get, default=None)
    return None if single is None or eligible[single] > (1 - margin) * current else single


def label(group) -> str:
    return "+".join(sorted(group)) if group else "nothing"


def main(paths: list[str]) -> None:
    for path in paths:
        report = json.loads(Path(path).read_text())
        kind = report["input"]["kind"]
        effects = (
            FRAME_PROBLEMS[report["attack"]].candidates
            if kind == "frame_pairs"
            else TABLE_EFFECTS[report["attack"]]
        )
        requires = {e.name: set(e.requires) for e in effects}
        margin = report["gain"]["selection_margin"]
        for step in report["selection"]["steps"]:
            if not step.get("tried") or step.get("paired"):
                continue
            scores = (step["tried"], step.get("set_aside", {}), step["validation_error"], requires, margin)
            before = group_taken(*scores, rule="furthest under need")
            after = group_taken(*scores, rule="lowest score")
            if before != after:
                print(f"{path}: at {sorted(step['effects'])} before {label(before)}, now {label(after)}")
                break


if __name__ == "__main__":
    main(sys.argv[1:])
