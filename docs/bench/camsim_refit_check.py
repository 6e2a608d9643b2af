"""Which laser blinding reports of a camsim batch would the refit check (``identify.refit_reasons``) change?

Usage: ``PYTHONPATH=. python docs/bench/camsim_refit_check.py OUTDIR`` (a ``camsim_core_batch.sh`` output made
with a version that searches the gain as ``log10_gain``). For every blinding report whose written model lost
effects in identification, prints what was dropped and what ``identify.refit_reasons`` says of each written effect,
given the written model's parameters and intervals from the report: the reports the check acts on.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames
from lerobot_phantom.calibration.identify import Interval, refit_reasons


def main() -> None:
    for path in sorted(Path(sys.argv[1]).glob("bt_*/camsim0/blinding_*/out/report.json")):
        report = json.loads(path.read_text())
        selected, written = (
            frozenset(report["selection"]["selected"]),
            frozenset(report["extended"]["effects"]),
        )
        if selected == written or not written:
            continue
        # the parameters' names and bounds, from the case's own pairs (the seed only picks pixel samples)
        problem = BlindingFrames(
            load_pairs(path.parent.parent / "pairs", max_side=CalibrateConfig().max_side), 0
        )
        fit = Fit(written, report["extended"]["params"])
        intervals = {k: Interval(**v) for k, v in report["extended"]["param_intervals"].items()}
        failing = [
            reason
            for effect in sorted(written)
            # a report keeps no bootstrap draws; no blinding effect has several nulls to judge jointly from them
            for reason in refit_reasons(problem, fit, intervals, effect, selected - written, ())
        ]
        print(
            f"{path.parts[-5]} {path.parts[-3]}: dropped {sorted(selected - written)}, wrote {sorted(written)}; "
            f"{'; '.join(failing) or 'passes'}"
        )


if __name__ == "__main__":
    main()
