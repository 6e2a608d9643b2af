"""The variance-by-position tests of every case of a ``camsim_core_batch.sh`` run: per case, the low end of the 90%
interval of the variance excess's eta2 by row and by column (the structure rule reports one above 0.02) and the
finding's size as a share of the base model's held-out MSE. Usage: ``python variance_lows.py OUTDIR``."""

import json
import sys
from pathlib import Path

for report in sorted(Path(sys.argv[1]).glob("bt_*/camsim0/*/out/report.json")):
    seed, case = report.parts[-5][3:], report.parts[-3]
    tests = json.loads(report.read_text())["unexplained_structure"].get("tests", [])
    cells = [
        f"{t['variable'].removeprefix('variance_by_')} {t['interval']['low']:.4f} (share {t['share_of_base_mse']:.2f})"
        for t in tests
        if t.get("variable", "").startswith("variance_by")
    ]
    print(f"{seed} {case:30s} {'  '.join(cells)}")
