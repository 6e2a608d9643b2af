"""camsim's unexplained rotation blur (``blur_rotation_unnamed``) on several master seeds: does the report say that
structure is left (the case test's requirement), and which variables it flags.

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/session45/rotation_structure_batch.py SEED...`` from a
checkout's root (its package is the one tested). Renders the case exactly as
``tests/calibration/test_independent_sim.py`` does for each master seed; one line per seed.
"""

import sys

sys.path.insert(0, "docs/bench")
from camsim_case_batch import run_on_master_seed

for seed in sys.argv[1:]:
    sim, result = run_on_master_seed("blur_rotation_unnamed", seed)
    report = result["report"]
    tests = report["unexplained_structure"]["tests"]
    clean_level = next(t for t in tests if t["variable"] == "clean_level")
    print(
        f"{seed} case seed {result['seed']} named {sorted(sim.named_causes(report))} "
        f"structure {'REPORTED' if sim.unexplained_structure(report) else 'MISSED'} "
        f"flagged {[t['variable'] for t in tests if t['significant']]} "
        f"clean_level eta2 {clean_level['value']:.4f} low {clean_level['interval']['low']:.4f} "
        f"chance {clean_level['chance']:.4f}",
        flush=True,
    )
