"""The laser blinding attack a calibration writes, fed the camera's own capture of the laser: a camsim blinding draw
(tests/calibration/test_independent_sim.py) calibrated by ``lerobot-phantom-calibrate`` (its own selection), then
``make_attack("laser_blinding", intensity=s, calibration=OUT, pattern=<the pair's pattern capture>)`` applied to
each held-out clean frame at that pair's intensity ``s``. RMSE in grey levels on the held-out pairs, beside the
calibration's own held-out RMSE (report.json), overall and on the pixels within a quarter of the frame's longer
side of the capture's spot (``pattern_centre``) and beyond.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python
docs/bench/session88/blinding_attack_from_calibration.py CASE:CASE_SEED...``
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import torch


def main() -> None:
    import pandas as pd
    import test_independent_sim as sim

    from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
    from lerobot_phantom.calibration.frame_models.laser_blinding import pattern_centre
    from lerobot_phantom.transforms.registry import make_attack

    torch.set_num_threads(1)
    for draw in sys.argv[1:]:
        name, seed = draw.split(":")
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            problem, fit_items, heldout = sim.drawn_split(name, int(seed), folder / "pairs")
            out = folder / "out"
            report = calibrate(
                CalibrateConfig(
                    attack="laser_blinding",
                    measured=str(folder / "pairs"),
                    out=str(out),
                    seed=int(seed) % 2**31,
                )
            )
            kwargs = json.loads((out / "calibrated.json").read_text())["kwargs"]
            fit = problem.fit(
                frozenset(report["extended"]["effects"]), fit_items
            )  # the report's (deterministic)
            table = pd.read_csv(folder / "pairs" / "pairs.csv")
            squared = {"fit": [], "attack": []}
            near = []
            for i in heldout:
                pair = problem.pairs[int(i)]
                capture = folder / "pairs" / table.loc[int(i), "pattern"]
                attack = make_attack(
                    "laser_blinding",
                    intensity=pair.intensity,
                    calibration=str(out),
                    pattern=str(capture),
                    seed=int(i),  # the frame exposure it draws (exposure_spread), reproducibly
                )
                squared["attack"].append(
                    (attack(pair.clean.unsqueeze(0).float())[0].double() - pair.attacked) ** 2
                )
                squared["fit"].append((problem.predict_pair(fit, int(i)) - pair.attacked) ** 2)
                cx, cy = pattern_centre(pair.pattern)
                ys, xs = torch.meshgrid(
                    torch.arange(pair.height, dtype=torch.float64),
                    torch.arange(pair.width, dtype=torch.float64),
                    indexing="ij",
                )
                near.append(
                    (torch.hypot(xs - cx, ys - cy) < max(pair.height, pair.width) / 4).expand(3, -1, -1)
                )
        mask = torch.cat([m.ravel() for m in near])

        def rmse(values, where=None):
            flat = torch.cat([v.ravel() for v in values])
            flat = flat if where is None else flat[where]
            return 255 * float(flat.mean().sqrt())

        print(
            f"{name} case seed {seed}, frames {tuple(problem.pairs[0].clean.shape)}, {len(heldout)} held-out pairs, "
            f"selected {report['extended']['effects']}, kwargs {kwargs}: calibration's held-out RMSE "
            f"{report['extended']['heldout_rmse']:.2f}; fit {rmse(squared['fit']):.2f} (near the spot "
            f"{rmse(squared['fit'], mask):.2f}, beyond {rmse(squared['fit'], ~mask):.2f}); attack fed the capture "
            f"{rmse(squared['attack']):.2f} (near {rmse(squared['attack'], mask):.2f}, beyond "
            f"{rmse(squared['attack'], ~mask):.2f})",
            flush=True,
        )


if __name__ == "__main__":
    main()
