"""One camsim case on several master seeds: whether the report says structure is left, and each flagged variable's
statistic with its 90% interval's low end.

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/session45/unexplained_case_batch.py CASE SEED...`` from a
checkout's root (its package is the one tested). Renders the case as ``tests/calibration/test_independent_sim.py``
does for each master seed; one line per seed.
"""

import importlib
import os
import sys
import tempfile

sys.path.insert(0, "tests/calibration")

name, seeds = sys.argv[1], sys.argv[2:]
for seed in seeds:
    os.environ["CAMSIM_SEED"] = seed
    sim = importlib.reload(importlib.import_module("test_independent_sim"))
    with tempfile.TemporaryDirectory() as root:
        result = sim.run_case(name, root)
    report = result["report"]
    flagged = [
        f"{t['variable']} {t['value']:.3f} (low {t['interval']['low']:.3f})"
        if "interval" in t
        else f"{t['variable']} {t['value']:.3f}"
        for t in report["unexplained_structure"]["tests"]
        if t["significant"]
    ]
    print(
        f"{name} {seed} case seed {result['seed']} named {sorted(sim.named_causes(report))} "
        f"structure {'REPORTED' if sim.unexplained_structure(report) else 'MISSED'} flagged {flagged}",
        flush=True,
    )
