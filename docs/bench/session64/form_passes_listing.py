"""Every camsim case in ``camsim_core_batch.sh`` OUTDIRs whose selection was repeated without a simpler form
(``selection.form_passes`` in its report.json): the first pass's and the repeat's selection and last scores, whether
the repeat was taken, and the effects written. Usage: ``python docs/bench/session64/form_passes_listing.py OUTDIR...``
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def main() -> None:
    cases = repeated = taken = 0
    for out in map(Path, sys.argv[1:]):
        for path in sorted(out.glob("bt_*/camsim0/*/out/report.json")):
            cases += 1
            report = json.loads(path.read_text())
            for repeat in report["selection"].get("form_passes", []):
                repeated += 1
                taken += repeat["taken"]
                print(
                    f"{path.parts[-5].removeprefix('bt_')} {path.parts[-3]}: first pass {repeat['first_selected']} "
                    f"at {repeat['first_validation_error']:.3f}; without {repeat['without']}: {repeat['selected']} "
                    f"at {repeat['validation_error']:.3f}; taken {repeat['taken']}; written "
                    f"{report['extended']['effects']}"
                )
    print(f"{cases} cases, {repeated} repeated without a simpler form, {taken} repeats taken")


if __name__ == "__main__":
    main()
