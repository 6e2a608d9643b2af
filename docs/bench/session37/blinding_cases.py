"""Runs camsim's laser-blinding cases for given master seeds and prints what each report names.
usage: python blinding_cases.py REPO ROOT SEED...   (REPO: the checkout whose tests/ and package are used)"""

import importlib
import os
import sys

repo, root, seeds = sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3:]]
sys.path.insert(0, f"{repo}/tests/calibration")
sys.path.insert(1, f"{repo}/tests")  # tests/sampling.py, which the case selection imports
sys.path.insert(0, repo)

CASES = ["blinding_null", "blinding_saturation", "blinding_auto_exposure", "blinding_halo"]
for master in seeds:
    os.environ["CAMSIM_SEED"] = str(master)
    for m in ("test_independent_sim",):
        sys.modules.pop(m, None)
    t = importlib.import_module("test_independent_sim")
    for name in CASES:
        case = t.CASE_BY_NAME[name]
        result = t.run_case(name, f"{root}/{master}")
        report = result["report"]
        named = t.named_causes(report)
        unplanted = named - case.planted - t.tolerated(case, result["camera"])
        missed = case.planted - named
        gain = report.get("extended", {}).get("params", {}).get("log10_gain")
        print(
            f"{master} {name:24s} tone={result['camera'].tone:6s} extended={sorted(report['extended']['effects'])} "
            f"missed={sorted(missed)} unplanted={sorted(unplanted)} log10_gain={gain}",
            flush=True,
        )
