"""Two whole-matrix runs on the same master seeds (``camsim_core_batch.sh`` layout), report by report: equal in every
key but the input path, timings and what session 77 added (``ratio_without``, ``redundant``, the criterion's words,
a finding's evidence text)? A report that differs is listed with the effects each side wrote and what was withdrawn
as redundant. Usage: ``python docs/bench/session77/same_reports_but_new_keys.py OUT_BEFORE OUT_AFTER``."""

import json
import sys
from pathlib import Path

NEW_KEYS = ("ratio_without", "redundant", "criterion", "evidence")


def comparable(value):
    if isinstance(value, dict):
        return {
            k: comparable(v)
            for k, v in value.items()
            if k != "input" and k not in NEW_KEYS and not any(t in k for t in ("seconds", "cpu", "time"))
        }
    if isinstance(value, list):
        return [comparable(v) for v in value]
    return value


def redundant_withdrawals(report: dict) -> list[str]:
    return [
        f"{w['effect']} (pass {w['pass']})"
        for w in report["selection"].get("withdrawn", [])
        if any("the effects selected after it hold what it brought" in r for r in w["reasons"])
    ]


def main() -> None:
    before, after = Path(sys.argv[1]), Path(sys.argv[2])
    same = 0
    for path in sorted(after.glob("bt_*/camsim0/*/out/report.json")):
        relative = path.relative_to(after)
        old_path = before / relative
        if not old_path.exists():
            continue
        old, new = json.loads(old_path.read_text()), json.loads(path.read_text())
        label = f"{relative.parts[0]} {relative.parts[2]}"
        if comparable(old) == comparable(new):
            same += 1
            print(f"{label}: identical", flush=True)
            continue
        print(
            f"{label}: DIFFERENT; before {old['extended']['effects']}, held-out {old['extended']['heldout_rmse']:.2f}; "
            f"after {new['extended']['effects']}, held-out {new['extended']['heldout_rmse']:.2f}; withdrawn as "
            f"redundant: {', '.join(redundant_withdrawals(new)) or 'none'}"
        )
    print(f"identical: {same}")


if __name__ == "__main__":
    main()
