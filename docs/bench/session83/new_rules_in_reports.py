"""Where session 83's three rules and session 84's dwell rule acted in a folder of calibration reports (a camsim matrix or run_camsim_case.py
output): every identification result whose reasons hold a rule's words, and every selection step that set a group
aside because the gamma sat at its low bound 1.

Usage: python docs/bench/session83/new_rules_in_reports.py OUTDIR"""

import json
import sys
from pathlib import Path

RULES = {
    "resonance is a path": "it covers an area, not the path of one motion",
    "clip bounds the clean frames": "the clip is not the sensor's",
    "resonance turns": "it does not slow to turn at the path's ends",
}


def reasons_of(report: dict):
    for result in report.get("identification", []):
        yield result["effect"], result.get("reasons", [])
    for earlier in report["selection"].get("earlier_passes", []):
        for result in earlier.get("identification", []):
            yield result["effect"], result.get("reasons", [])


def main(root: Path) -> None:
    counts = dict.fromkeys([*RULES, "gamma at its low bound 1"], 0)
    reports = sorted(root.glob("bt_*/camsim0/*/out/report.json"))
    for path in reports:
        report = json.loads(path.read_text())
        where = f"{path.parts[-5].removeprefix('bt_')} {path.parts[-3]}"
        text = json.dumps(report["selection"]) + json.dumps(report.get("identification", []))
        for rule, words in RULES.items():
            if words in text:
                counts[rule] += 1
                print(f"{where}: {rule} (written: {report['extended']['effects']})")
        if "gamma at its low bound 1 " in text:
            counts["gamma at its low bound 1"] += 1
            print(
                f"{where}: gamma at its low bound 1 in a set-aside (written: {report['extended']['effects']})"
            )
    print(f"{len(reports)} reports; " + ", ".join(f"{k}: {v}" for k, v in counts.items()))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
