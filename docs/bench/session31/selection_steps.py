"""The selection record of camsim case reports, step by step: each step's model and validation score, the groups
tried there (best first, with why a group was set aside), what selection withdrew, and each identified effect's
fitted parameters. Usage: ``python docs/bench/session31/selection_steps.py REPORT_JSON...`` (``--best N``: groups
shown per step, default 8)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("reports", nargs="+")
    parser.add_argument("--best", type=int, default=8)
    args = parser.parse_args()
    for path in args.reports:
        report = json.loads(Path(path).read_text())
        print(f"== {path}")
        for step in report["selection"]["steps"]:
            print(
                f"{step['effects']} {step['validation_error']:.3f}{' (inside a group)' if step.get('paired') else ''}"
            )
            ranked = sorted(step.get("tried", {}).items(), key=lambda kv: kv[1])[: args.best]
            for group, score in ranked:
                why = step.get("set_aside", {}).get(group, "")
                print(f"    {group} {score:.3f}{'  set aside: ' + why if why else ''}")
        print(f"withdrawn {report['selection'].get('withdrawn')}")
        for item in report["identification"]:
            params = {k: round(v, 4) for k, v in item["params"].items()}
            print(f"{item['effect']} {item['status']} {params} {item['reasons']}")
        print(
            f"held-out {report['base']['heldout_rmse']:.3f} -> {report['extended']['heldout_rmse']:.3f}, "
            f"structure: {report['unexplained_structure']['summary'][:160]}"
        )


if __name__ == "__main__":
    main()
