"""Two report.json files of the same pairs and seed at two packages: per structure test, identical or not, and
whether the rest of the report is identical. Usage: ``python same_draws_check.py OLD_REPORT NEW_REPORT``.
Session 73 ran it on camsim's em_strip_null of master seed 913236811 (case seed 3176451851, calibration seed
case seed % 2**31, pairs rendered by variance_probe.py), calibrated by ``calibrate(CalibrateConfig(...))`` at
e9bbfe9 and at 2667ea7."""

import json
import sys
from pathlib import Path

old, new = (json.loads(Path(path).read_text()) for path in sys.argv[1:3])
old_tests = {t["variable"]: t for t in old["unexplained_structure"]["tests"]}
new_tests = {t["variable"]: t for t in new["unexplained_structure"]["tests"]}
for name, test in old_tests.items():
    verdict = "identical" if test == new_tests.get(name) else "differs"
    print(f"{name:28s} {verdict:9s} significant {test['significant']} -> {new_tests[name]['significant']}")
rest = [k for k in old if k != "unexplained_structure" and old[k] != new.get(k)]
print("the rest of report.json:", "identical" if not rest else f"differs in {rest}")
