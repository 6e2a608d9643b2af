"""Two runs of ``docs/bench/stripe_table_seeds.py`` on one table, split by split: the written model's held-out error
with its interval, the named causes, and the largest relative change of a fitted parameter.

Usage: ``python docs/bench/session54/probes/compare_table_seeds.py BEFORE.json AFTER.json``
"""

import json
import sys
from pathlib import Path

before, after = (json.loads(Path(path).read_text())["runs"] for path in sys.argv[1:3])
for seed in before:
    b, a = before[seed], after[seed]
    change = max(
        (
            abs(a["extended_params"][k] - v) / max(abs(v), 1e-300)
            for k, v in b["extended_params"].items()
            if k in a["extended_params"]
        ),
        default=0.0,
    )

    def held(run):
        h = run["extended_heldout_rmse"]
        return f"{h['estimate']:.4f} [{h['low']:.3f}, {h['high']:.3f}]"

    same = (
        "same causes"
        if b["named_causes"] == a["named_causes"]
        else f"{b['named_causes']} -> {a['named_causes']}"
    )
    print(f"{seed}: held-out {held(b)} -> {held(a)}; {same}; largest relative parameter change {change:.2e}")
