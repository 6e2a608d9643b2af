"""Two records of the same runs compared run by run: ``stripe_table_seeds.py`` outputs (one run per split) or
``calibration_shared_data.py`` outputs (one run per input). Prints, per run, the written model's held-out RMSE and
its interval before -> after, then whether the named causes, the effects not identified and the fitted parameters
changed (the largest relative change of a parameter), and the intervals' draws.

    python docs/bench/session44/compare_runs.py BEFORE.json AFTER.json
"""

import json
import sys
from pathlib import Path


def interval(record: dict) -> str:
    return f"{record['estimate']:.4f} [{record['low']:.3f}, {record['high']:.3f}] ({record['draws']} draws)"


def largest_relative_change(before: dict, after: dict) -> float:
    if before.keys() != after.keys():
        return float("inf")
    return max(
        (abs(after[k] - v) / max(abs(v), 1e-300) for k, v in before.items() if v != after[k]),
        default=0.0,
    )


before_runs = json.loads(Path(sys.argv[1]).read_text())["runs"]
after_runs = json.loads(Path(sys.argv[2]).read_text())["runs"]
same_model = 0
for name, before in before_runs.items():
    after = after_runs[name]
    line = [
        f"{name}: held-out {interval(before['extended_heldout_rmse'])} -> {interval(after['extended_heldout_rmse'])}"
    ]
    for key in ("named_causes", "not_identified"):
        if before[key] != after[key]:
            line.append(f"{key} {before[key]} -> {after[key]}")
    change = largest_relative_change(before["extended_params"], after["extended_params"])
    line.append(f"largest relative parameter change {change:.2e}")
    if change == 0.0 and all(before[k] == after[k] for k in ("named_causes", "not_identified")):
        same_model += 1
    print("; ".join(line))
print(
    f"{same_model} of {len(before_runs)} runs write the same model (causes, effects not identified, parameters)"
)
