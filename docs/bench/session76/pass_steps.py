"""Every selection pass of a calibration report, step by step: the model after each step, its validation error, and
the best few groups the step scored (with why any was set aside); then what was withdrawn and why. Usage: ``python
docs/bench/session76/pass_steps.py LABEL=REPORT_JSON...``."""

import json
import sys
from pathlib import Path


def print_steps(name: str, steps: list[dict]) -> None:
    for index, step in enumerate(steps):
        print(f"  {name} step {index}: {'+'.join(step['effects']) or 'base'} {step['validation_error']:.3f}")
        for group, score in sorted(step["tried"].items(), key=lambda kv: kv[1])[:4]:
            aside = step.get("set_aside", {}).get(group)
            print(f"      tried {group} {score:.3f}" + (f" (set aside: {aside})" if aside else ""))


for argument in sys.argv[1:]:
    label, path = argument.split("=", 1)
    report = json.loads(Path(path).read_text())
    selection = report["selection"]
    print(f"{label}: written {report['extended']['effects']}")
    for earlier in selection["earlier_passes"]:
        print(f"  pass {earlier['pass']} selected {earlier['selected']}, withdrawn {earlier['withdrawn']}")
        print_steps(f"pass {earlier['pass']}", earlier.get("steps", []))
    print_steps("written pass", selection["steps"])
    for withdrawal in selection["withdrawn"]:
        print(f"  withdrawn {withdrawal['effect']} (pass {withdrawal['pass']}): {withdrawal['reasons']}")
