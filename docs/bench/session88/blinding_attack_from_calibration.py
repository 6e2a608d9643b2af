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

import sys

import torch
from calibrated_draws import calibrated_draws


def main() -> None:
    from lerobot_phantom.transforms.physics import pattern_centre
    from lerobot_phantom.transforms.registry import make_attack

    for draw in calibrated_draws("laser_blinding", sys.argv[1:]):
        problem, report, kwargs = draw.problem, draw.report, draw.kwargs
        fit = draw.fit()
        squared = {"fit": [], "attack": []}
        near = []
        for i in draw.heldout:
            pair = problem.pairs[int(i)]
            attack = make_attack(
                "laser_blinding",
                intensity=pair.intensity,
                calibration=str(draw.out),
                pattern=str(draw.folder / "pairs" / f"pattern_{int(i):03d}.png"),  # camsim.write_pairs' names
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
            near.append((torch.hypot(xs - cx, ys - cy) < max(pair.height, pair.width) / 4).expand(3, -1, -1))
        mask = torch.cat([m.ravel() for m in near])

        def rmse(values, where=None):
            flat = torch.cat([v.ravel() for v in values])
            flat = flat if where is None else flat[where]
            return 255 * float(flat.mean().sqrt())

        print(
            f"{draw.name} case seed {draw.seed}, frames {tuple(problem.pairs[0].clean.shape)}, "
            f"{len(draw.heldout)} held-out pairs, selected {report['extended']['effects']}, kwargs {kwargs}: "
            f"calibration's held-out RMSE {report['extended']['heldout_rmse']:.2f}; fit {rmse(squared['fit']):.2f} "
            f"(near the spot {rmse(squared['fit'], mask):.2f}, beyond {rmse(squared['fit'], ~mask):.2f}); attack fed "
            f"the capture {rmse(squared['attack']):.2f} (near {rmse(squared['attack'], mask):.2f}, beyond "
            f"{rmse(squared['attack'], ~mask):.2f})",
            flush=True,
        )


if __name__ == "__main__":
    main()
