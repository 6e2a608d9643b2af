"""Which laser blinding reports of a camsim batch would the refit check (``identify.refit_reasons``) change?

Usage: ``PYTHONPATH=. python docs/bench/camsim_refit_check.py OUTDIR`` (a ``camsim_core_batch.sh`` output made
with a version that searches the gain as ``log10_gain``). For every blinding report whose written model lost
effects in identification, prints what was dropped and any of the written model's own parameters at a bound of its
range, or any null-value interval that includes its null: the reports the check acts on.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames
from lerobot_phantom.calibration.identify import at_bound


def main() -> None:
    for path in sorted(Path(sys.argv[1]).glob("bt_*/camsim0/blinding_*/out/report.json")):
        report = json.loads(path.read_text())
        selected, written = set(report["selection"]["selected"]), set(report["extended"]["effects"])
        if selected == written or not written:
            continue
        params, intervals = report["extended"]["params"], report["extended"]["param_intervals"]
        failing = [
            f"{p.name} = {params[p.name]:.3g} at its {side} bound"
            for p in BlindingFrames.param_specs(None, frozenset(written))
            if (side := at_bound(params[p.name], p.low, p.high)) and not (side == "low" and p.low_limit)
        ]
        for effect in written:
            for name, null in BlindingFrames.null_values(None, effect).items():
                if intervals[name]["low"] <= null <= intervals[name]["high"]:
                    failing.append(f"the interval of {name} includes its null {null}")
        print(
            f"{path.parts[-5]} {path.parts[-3]}: dropped {sorted(selected - written)}, wrote {sorted(written)}; "
            f"{'; '.join(failing) or 'passes'}"
        )


if __name__ == "__main__":
    main()
