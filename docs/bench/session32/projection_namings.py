"""The written model, held-out RMSE and fitted light spread (reference pixels, when written) of every light projection
case report a camsim batch kept.

Usage: ``python docs/bench/session32/projection_namings.py OUTDIR...`` (``camsim_core_batch.sh`` output folders).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def main() -> None:
    for outdir in sys.argv[1:]:
        for path in sorted(Path(outdir).glob("bt_*/camsim0/projection_*/out/report.json")):
            report = json.loads(path.read_text())
            seed, case = path.parts[-5].removeprefix("bt_"), path.parts[-3]
            spread = report["extended"].get("params", {}).get("spread_ref_px")
            print(
                f"{seed} {case}: {sorted(report['extended']['effects'])}, held-out "
                f"{report['base']['heldout_rmse']:.2f} -> {report['extended']['heldout_rmse']:.2f}"
                + ("" if spread is None else f", spread {spread:.2f} reference px")
            )


if __name__ == "__main__":
    main()
