"""Two runs of ``docs/bench/stripe_table_seeds.py`` on the same table and split seeds (before and after a change):
per split, the written model's held-out RMSE (estimate and interval), whether the named causes are the same, and the
largest relative change of a fitted parameter; then the mean and median of the written held-out RMSE.

    python docs/bench/session39/stripe_table_runs_compare.py BEFORE.json AFTER.json
"""

import json
import sys

import numpy as np


def main(before_path: str, after_path: str) -> None:
    with open(before_path) as before_file, open(after_path) as after_file:
        before, after = json.load(before_file)["runs"], json.load(after_file)["runs"]
    for split in before:
        one, two = before[split], after[split]
        params = one["extended_params"]
        if params.keys() == two["extended_params"].keys():
            change = max(abs(two["extended_params"][k] - v) / max(abs(v), 1e-30) for k, v in params.items())
            moved = f"largest relative parameter change {change:.2e}"
        else:
            moved = f"parameters {sorted(params)} -> {sorted(two['extended_params'])}"
        held = [run["extended_heldout_rmse"] for run in (one, two)]
        cells = [f"{h['estimate']:.4f} [{h['low']:.3f}, {h['high']:.3f}]" for h in held]
        named = (
            "same causes"
            if one["named_causes"] == two["named_causes"]
            else (f"causes {one['named_causes']} -> {two['named_causes']}")
        )
        print(f"split {split}: held-out {cells[0]} -> {cells[1]}; {named}; {moved}")
    for label, runs in (("before", before), ("after", after)):
        values = np.array([run["extended_heldout_rmse"]["estimate"] for run in runs.values()])
        print(
            f"{label}: mean {values.mean():.4f}, median {np.median(values):.4f} rows over {len(values)} splits"
        )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
