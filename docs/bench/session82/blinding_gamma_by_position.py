"""A lead, not a rule: light projection's tone-position check (``frame_models/light_projection.py``: a tone curve
acts on every pixel alike, so the gamma refitted on the fit pairs' pixels nearest the centre and on the rest must
find the whole frame's) applied to laser blinding reports, the centre being the laser spot's.

Usage: PYTHONPATH=. python docs/bench/session82/blinding_gamma_by_position.py CASE_FOLDER... (each with pairs/ and
out/report.json, as out_of_library_probe.py writes them). Its output blinding_gamma_by_position_b4628c1.txt was made
at b4628c1, where TONE_POSITION_EXCESS lived in frame_models/light_projection.py (imported from there then; the
package's check, fa6fea5, now holds it in frame_models/common.py)."""

import json
import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.frame_models.common import TONE_POSITION_EXCESS, load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames


def main(folders: list[Path]) -> None:
    for folder in folders:
        report = json.loads((folder / "out" / "report.json").read_text())
        seed = report["split"]["seed"]
        problem = BlindingFrames(load_pairs(folder / "pairs", max_side=CalibrateConfig().max_side), seed)
        fit_items, _ = seeded_split(problem.n_items, 0.2, seed)
        effects = frozenset(report["extended"]["effects"]) | {"sensor_gamma"}
        halves = [
            problem.fit_on_pixels(effects, fit_items, rows).params["gamma"]
            for rows in problem.position_halves(fit_items)
        ]
        whole = report["extended"]["params"].get("gamma")
        departure = float(np.mean(halves)) - 1.0
        verdict = (
            "no written gamma"
            if whole is None
            else f"whole / halves' departure {abs((whole - 1.0) / departure):.2f} (the check's limit "
            f"{TONE_POSITION_EXCESS:g})"
        )
        print(
            f"{folder.name}: written {report['extended']['effects']}, gamma {whole}; near the spot / the rest "
            f"{halves[0]:.3f} / {halves[1]:.3f}; {verdict}",
            flush=True,
        )


if __name__ == "__main__":
    main([Path(p) for p in sys.argv[1:]])
