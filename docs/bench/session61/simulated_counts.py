"""Does the calibrated EM truncation simulate the counts of rows the measured frames lost? (session 61)

``PYTHONPATH=. python docs/bench/session61/simulated_counts.py BEFORE_ROOT AFTER_ROOT CASE MASTER_SEED...``: for
each master seed, the frame pairs ``count_spread_cases.py`` rendered (``ROOT/<seed>/<case>/pairs``) and the
``calibrated.json`` each package wrote from them (``ROOT/<seed>/<case>/out``). Every held-out frame's count is
registered (the band searched on the frame itself, as the report's "registered" figure), and each calibration's
transform, ``make_attack("em_truncation", calibration=DIR)``, draws 4000 ratios at that frame's intensity: printed
are the share of held-out frames whose count the simulation ever produces and the mean share of draws that
produce it. Before session 61 the calibrated transform drew one count per intensity.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from report_folder import report_problem

from lerobot_phantom.transforms.registry import make_attack

DRAWS = 4000


def frame_counts(root: Path, case: str, seed: str) -> list[tuple[float, int, int]]:
    """(intensity, height, registered count) of each held-out frame."""
    _, problem, _, heldout = report_problem(root / seed / case, "em_truncation")
    frames = []
    for index in heldout:
        pair = problem.pairs[int(index)]
        frames.append((pair.intensity, pair.height, problem.placement(False, int(index))[0]))
    return frames


def simulated_share(calibration: Path, intensity: float, height: int, count: int) -> float:
    attack = make_attack("em_truncation", calibration=str(calibration), seed=0)
    params = attack.sample_params(
        DRAWS,
        height,
        8,
        intensity=torch.full((DRAWS,), intensity),
        generator=torch.Generator().manual_seed(1),
    )
    return float(np.mean([int(height * r) == count for r in params["ratio"].tolist()]))


def main() -> None:
    before, after, case, seeds = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3], sys.argv[4:]
    totals = {"before": [], "after": []}
    for seed in seeds:
        frames = frame_counts(after, case, seed)
        line = []
        for label, root in (("before", before), ("after", after)):
            shares = [simulated_share(root / seed / case / "out", s, h, n) for s, h, n in frames]
            totals[label] += shares
            line.append(
                f"{label} produced {sum(x > 0 for x in shares)}/{len(shares)} mean share {np.mean(shares):.3f}"
            )
        counts = ", ".join(f"{n} rows at {s:.2f}" for s, _, n in frames)
        print(f"{case} {seed}: held-out {counts} | " + " | ".join(line), flush=True)
    for label, shares in totals.items():
        print(
            f"# {label}: {sum(x > 0 for x in shares)} of {len(shares)} held-out frames' counts produced by the "
            f"calibrated transform; mean share of draws producing the frame's count {np.mean(shares):.3f}"
        )


if __name__ == "__main__":
    main()
