"""camsim's blinding_halo case alone, for fresh master seeds: what each report names, and the fitted laser gain.

usage: python halo_cases.py REPO ROOT SEED...   (REPO: the checkout whose package and tests/ are used; ROOT: scratch)
"""

import importlib
import os
import sys

repo, root, seeds = sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3:]]
sys.path.insert(0, f"{repo}/tests/calibration")
sys.path.insert(1, f"{repo}/tests")  # tests/sampling.py, which the case selection imports
sys.path.insert(0, repo)
for master in seeds:
    os.environ["CAMSIM_SEED"] = str(master)
    sys.modules.pop("test_independent_sim", None)
    t = importlib.import_module("test_independent_sim")
    case = t.CASE_BY_NAME["blinding_halo"]
    result = t.run_case("blinding_halo", f"{root}/{master}")
    report = result["report"]
    named = t.named_causes(report)
    print(
        f"{master} tone={result['camera'].tone:6s} extended={sorted(report['extended']['effects'])} "
        f"missed={sorted(case.planted - named)} unplanted={sorted(named - case.planted - t.tolerated(case, result['camera']))} "
        f"log10_gain={report['extended']['params'].get('log10_gain')}",
        flush=True,
    )
