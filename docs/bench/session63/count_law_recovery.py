"""Does EM truncation's count law recover the law that made the counts? (session 63)

``PYTHONPATH=PACKAGE python docs/bench/session63/count_law_recovery.py run design|check OUT.jsonl`` draws, for each
scenario of the set and each replicate (fixed seeds), fit frames and ``HELD`` held-out frames from the calibrated
transform itself (``EMTruncation(ratio_per_intensity=a, ratio_jitter=d).sample_params``, counts ``int(h r)`` as
the transform loses them), fits ``count_law`` on the fit frames' counts and scores every held-out count with the
law the calibration predicts held-out frames with (``TruncationFrames.predicted_counts`` at the frame's intensity;
``-inf`` where the count has no probability). One JSON line per replicate; runs on the package before and after
session 63. ``design`` holds the draws the change was chosen on, ``check`` others written down after it.
``python docs/bench/session63/count_law_recovery.py compare BEFORE.jsonl AFTER.jsonl`` compares two runs paired by
replicate.
"""

from __future__ import annotations

import json
import math
import statistics
import sys

import numpy as np
import torch
from scipy.stats import binomtest

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.em_truncation import TruncationFrames, count_law
from lerobot_phantom.transforms.em_truncation import EMTruncation

HELD, REPLICATES = 10, 200
# (name, slope a, jitter d in rows, lowest intensity, share of frames at zero intensity, height, fit frames)
DESIGN = [  # the draws session 63's change was chosen on
    ("strong attacks, d 1 row", 0.25, 1.0, 0.3, 0.0, 48, 10),
    ("weak to strong, d 1 row", 0.25, 1.0, 0.0, 0.0, 48, 10),
    ("weak to strong, d 2 rows", 0.25, 2.0, 0.0, 0.0, 48, 10),
    ("weak to strong, d 0.5 row", 0.25, 0.5, 0.0, 0.0, 48, 10),
    ("weak to strong and unattacked, d 1 row", 0.25, 1.0, 0.0, 0.2, 48, 10),
]
CHECK = [  # written down after the change, before any was run, other seeds
    ("check: 6 frames of 72 rows, d 1.5 rows", 0.2, 1.5, 0.2, 0.0, 72, 6),
    ("check: 20 frames of 60 rows, d 0.7 row, a tenth unattacked", 0.3, 0.7, 0.0, 0.1, 60, 20),
    ("check: 4 frames of 120 rows, d 2 rows", 0.25, 2.0, 0.3, 0.0, 120, 4),
]
SETS = {"design": (DESIGN, 0), "check": (CHECK, 1_000_000)}


class _Counts:
    """The frames TruncationFrames.predicted_counts reads: an intensity and a height."""

    def __init__(self, intensity: float, height: int) -> None:
        self.intensity, self.height = intensity, height


def draw(slope: float, jitter: float, lowest: float, unattacked: float, height: int, n: int, seed: int):
    generator = torch.Generator().manual_seed(seed)
    intensity = lowest + (1 - lowest) * torch.rand(n, generator=generator, dtype=torch.float64)
    intensity[torch.rand(n, generator=generator) < unattacked] = 0.0
    attack = EMTruncation(ratio_per_intensity=slope, ratio_jitter=jitter)
    params = attack.sample_params(n, height, 2, intensity=intensity.float(), generator=generator)
    counts = np.array([int(height * r) for r in params["ratio"].tolist()])
    return intensity.float().double().numpy(), counts


def held_out_log_probability(fit: Fit, height: int, intensities: np.ndarray, counts: np.ndarray) -> float:
    problem = TruncationFrames.__new__(TruncationFrames)
    problem.pairs = [_Counts(float(s), height) for s in intensities]
    total = 0.0
    for index, count in enumerate(counts):
        predicted, weights = problem.predicted_counts(fit, index)
        hit = weights[predicted == count]
        total += math.log(float(hit[0])) if len(hit) else -math.inf
    return total / len(counts)


def run(path: str, which: str) -> None:
    scenarios, offset = SETS[which]
    with open(path, "w") as out:
        for number, (name, slope, rows, lowest, unattacked, height, frames) in enumerate(scenarios):
            jitter = rows / height
            for replicate in range(REPLICATES):
                seed = offset + 1000 * number + replicate
                fit_s, fit_n = draw(slope, jitter, lowest, unattacked, height, frames, 2 * seed)
                held_s, held_n = draw(slope, jitter, lowest, unattacked, height, HELD, 2 * seed + 1)
                law = count_law(fit_n, np.full(frames, height), fit_s)
                if isinstance(law, tuple):  # before session 63's CountLaw: (lowest, highest, jitter)
                    low, high, fitted_jitter = law
                    jitters = [fitted_jitter]
                else:
                    low, high, fitted_jitter, jitters = law.lowest, law.highest, law.jitter, list(law.jitters)
                fit = Fit(
                    frozenset(),
                    {"ratio_per_intensity": 0.5 * (low + high), "ratio_jitter": fitted_jitter},
                    {"slope_range": [low, high], "jitters": jitters},
                )
                record = {
                    "scenario": name,
                    "replicate": replicate,
                    "slope": slope,
                    "jitter": jitter,
                    "height": height,
                    "fitted_slope": 0.5 * (low + high),
                    "fitted_jitter": fitted_jitter,
                    "held_out_log_probability": held_out_log_probability(fit, height, held_s, held_n),
                }
                out.write(json.dumps(record) + "\n")


def load(path: str) -> dict:
    rows = {}
    with open(path) as handle:
        for line in handle:
            row = json.loads(line)
            rows.setdefault(row["scenario"], {})[row["replicate"]] = row
    return rows


def compare(before_path: str, after_path: str) -> None:
    before, after = load(before_path), load(after_path)
    for name in before:
        pairs = [(before[name][k], after[name][k]) for k in before[name]]
        print(
            f"{name}: {len(pairs)} replicates, true slope {pairs[0][0]['slope']:.3f}, jitter "
            f"{pairs[0][0]['jitter'] * pairs[0][0].get('height', 48):.2f} rows"
        )
        for label, index in (("before", 0), ("after", 1)):
            rows = [pair[index] for pair in pairs]
            jitter_rows = [r["fitted_jitter"] * r.get("height", 48) for r in rows]
            slopes = [r["fitted_slope"] for r in rows]
            scores = [r["held_out_log_probability"] for r in rows]
            finite = [s for s in scores if math.isfinite(s)]
            quartiles = statistics.quantiles(jitter_rows, n=4)
            print(
                f"  {label}: jitter median {statistics.median(jitter_rows):.2f} rows (quartiles "
                f"{quartiles[0]:.2f}-{quartiles[2]:.2f}), slope median {statistics.median(slopes):.4f}; held-out "
                f"counts with no probability in {len(scores) - len(finite)} replicates, mean log probability per "
                f"frame {statistics.mean(finite):.3f} where finite"
            )
        both = [(b["held_out_log_probability"], a["held_out_log_probability"]) for b, a in pairs]
        better = sum(a > b + 1e-9 for b, a in both)
        worse = sum(b > a + 1e-9 for b, a in both)
        finite = [(b, a) for b, a in both if math.isfinite(b) and math.isfinite(a)]
        print(
            f"  where both are finite ({len(finite)} replicates): mean log probability per frame "
            f"{statistics.mean(b for b, _ in finite):.4f} -> {statistics.mean(a for _, a in finite):.4f}, "
            f"median paired change {statistics.median(a - b for b, a in finite):+.4f}"
        )
        p_value = binomtest(better, better + worse).pvalue
        print(
            f"  held-out log probability, paired: {better} better, {worse} worse, {len(both) - better - worse} same "
            f"(exact sign test p = {p_value:.2g})"
        )


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "run" and sys.argv[2] in SETS:
        run(sys.argv[3], sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        compare(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
