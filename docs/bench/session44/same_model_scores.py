"""Models that one selection pass scored more than once, with cross-validated scores more than 5% apart: the same
effects reached from different warm starts (a group's start in one step, the chosen model's fold fits in the next).
Reads report.json files (every pass: ``selection.earlier_passes`` and the last pass's steps) and prints one line per
such model, then how many reports were read.

    python docs/bench/session44/same_model_scores.py REPORT.json [REPORT.json ...]
"""

import json
import sys
from pathlib import Path


def scores_by_model(steps: list[dict]) -> dict[frozenset, list[tuple[int, str, float]]]:
    seen: dict[frozenset, list[tuple[int, str, float]]] = {}
    for index, step in enumerate(steps):
        chosen = frozenset(step["effects"])
        seen.setdefault(chosen, []).append((index, "the step's model", step["validation_error"]))
        for label, score in step["tried"].items():
            seen.setdefault(chosen | frozenset(label.split("+")), []).append((index, label, score))
    return seen


reports = sorted({Path(p).resolve() for p in sys.argv[1:]})
for path in reports:
    report = json.loads(path.read_text())
    passes = [p["steps"] for p in report["selection"].get("earlier_passes", [])] + [
        report["selection"]["steps"]
    ]
    for number, steps in enumerate(passes, start=1):
        for model, entries in scores_by_model(steps).items():
            scores = [score for _, _, score in entries]
            if len(entries) > 1 and max(scores) > 1.05 * min(scores):
                print(f"{path.parent.parent}: pass {number}, {sorted(model)}: {entries}")
print(f"{len(reports)} reports read")
