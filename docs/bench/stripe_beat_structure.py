"""Is a frame-rate beat in a stripe table reported as unexplained structure? One line per STRIPES_SEED.

Replays tests/calibration/test_stripes.py::test_an_unnamed_stripe_effect_is_reported_as_structure_not_as_a_cause
for each seed given (the same table, the same calibration seed) and prints the named effects, whether structure
remains, and the frequency test's eta squared, the low end of its 90% bootstrap interval, the chance level it must
exceed (the permutation null's 99th percentile before d209789, its 1 - 0.01/k quantile since), and its permutation
p-value.

    python docs/bench/stripe_beat_structure.py OUTDIR SEED [SEED ...]
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

# the test module reads STRIPES_SEED on import; each seed below is passed explicitly
os.environ.setdefault("STRIPES_SEED", "0")
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "calibration"))

from test_stripes import band_table

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main(out: Path, seeds: list[int]) -> None:
    for seed in seeds:
        folder = out / str(seed)
        folder.mkdir(parents=True, exist_ok=True)
        band_table(folder / "beat.csv", np.random.default_rng([seed, 5]), 600, flicker=0.4)
        config = CalibrateConfig(
            attack="laser_color_strip",
            measured=str(folder / "beat.csv"),
            out=str(folder / "out"),
            image_height=600,
            seed=seed % 1000,
        )
        report = calibrate(config)
        structure = report["unexplained_structure"]
        test = next(t for t in structure["tests"] if t["variable"] == "frequency_hz")
        print(
            seed,
            report["extended"]["effects"],
            structure["structure_remains"],
            f"eta={test['value']:.3f} low={test['interval']['low']:.3f} chance={test['chance']:.3f} "
            f"p={test['p_value']:.4f}",
            flush=True,
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]), [int(s) for s in sys.argv[2:]])
