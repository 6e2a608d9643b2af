"""Two runs of ``session73/variance_probe.py`` on the same master seeds, report by report: equal in every key but
the input path and timings? Usage: ``python docs/bench/session75/same_reports_check.py OUT_A OUT_B``."""

import json
import sys
from pathlib import Path


def without_run_details(value):
    if isinstance(value, dict):
        return {
            k: without_run_details(v)
            for k, v in value.items()
            if k != "input" and not any(t in k for t in ("seconds", "cpu", "time"))
        }
    if isinstance(value, list):
        return [without_run_details(v) for v in value]
    return value


def main() -> None:
    first, second = Path(sys.argv[1]), Path(sys.argv[2])
    for path in sorted(second.glob("bt_*/camsim0/*/out/report.json")):
        relative = path.relative_to(second)
        a = without_run_details(json.loads((first / relative).read_text()))
        b = without_run_details(json.loads(path.read_text()))
        print(f"{relative.parts[0]} {relative.parts[2]}: {'identical' if a == b else 'DIFFERENT'}")


if __name__ == "__main__":
    main()
