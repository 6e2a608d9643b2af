"""Where the exposure-50 sweep's drift evidence falls in each held-out split of a stripe table: its videos at 10-30%
duty (the ones a drift of a third of a period cuts, session 33) among the fit rows and the held-out rows, and the
chance that an item bootstrap draw of the fit rows holds none of them, (1 - k/n)^n for k such rows of n.

Prints split composition only (duty settings), no measured value.

Usage: ``python docs/bench/session34/evidence_rows.py TABLE --image-height 720 --exposure-unit-s 1e-6``
"""

import argparse
from pathlib import Path

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.stripes import StripeProblem

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("table", type=Path)
parser.add_argument("--image-height", type=int, required=True)
parser.add_argument("--exposure-unit-s", type=float, required=True)
parser.add_argument("--recording", default="drift_25Hz_exposure50")
args = parser.parse_args()
problem = StripeProblem(args.table, image_height=args.image_height, exposure_unit_s=args.exposure_unit_s)
recording = problem.drift_names.index(args.recording)
for seed in range(10):
    fit, heldout = seeded_split(problem.n_items, 0.2, seed)

    def duties(items):
        return sorted(
            round(100 * problem.duty[i])
            for i in items
            if problem.recording[i] == recording and problem.duty[i] >= 0.1
        )

    evidence = duties(fit)
    none = (1 - len(evidence) / len(fit)) ** len(fit)
    print(
        f"split {seed}: fit rows at {evidence}% duty, held-out at {duties(heldout)}%; "
        f"a bootstrap draw of the {len(fit)} fit rows holds none of them with chance {none:.3f}"
    )
