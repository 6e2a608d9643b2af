"""One camsim case on several master seeds: whether the report says structure is left, and each flagged variable's
statistic with its 90% interval's low end.

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/session45/unexplained_case_batch.py CASE SEED...`` from a
checkout's root (its package is the one tested). Renders the case as ``tests/calibration/test_independent_sim.py``
does for each master seed; one line per seed.
"""

import sys

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

name, seeds = sys.argv[1], sys.argv[2:]
for seed in seeds:
    sim, result = run_on_master_seed(name, seed)
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
