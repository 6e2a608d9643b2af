"""The ultrasound blur attack a calibration writes, as a user runs it: a camsim blur draw
(tests/calibration/test_independent_sim.py) calibrated by ``lerobot-phantom-calibrate`` (its own selection), then
``make_attack("ultrasound_blur", intensity=s, calibration=OUT)`` applied to each held-out clean frame at that pair's
intensity ``s`` through the attack's own sampler. RMSE in grey levels on the held-out pairs, beside the calibration's
own held-out RMSE (report.json) and the same ``calibrated.json`` options without ``displacement_per_intensity_px``
(what packages before session 88 wrote: the paper's lengths on its diagonal, scaled per axis).

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python
docs/bench/session88/blur_attack_from_calibration.py CASE:CASE_SEED...``
"""

from __future__ import annotations

import sys

import torch
from calibrated_draws import calibrated_draws


def main() -> None:
    from lerobot_phantom.transforms.registry import make_attack

    for draw in calibrated_draws("ultrasound_blur", sys.argv[1:]):
        problem, report, kwargs = draw.problem, draw.report, draw.kwargs
        paper_length = {k: v for k, v in kwargs.items() if k != "displacement_per_intensity_px"}
        errors: dict[str, list[torch.Tensor]] = {"calibrated.json": [], "without its displacement": []}
        for i in draw.heldout:
            pair = problem.pairs[int(i)]
            clean = pair.clean.unsqueeze(0)
            calibrated = make_attack("ultrasound_blur", intensity=pair.intensity, calibration=str(draw.out))
            errors["calibrated.json"].append(calibrated(clean)[0] - pair.attacked)
            paper = make_attack("ultrasound_blur", intensity=pair.intensity, **paper_length)
            errors["without its displacement"].append(paper(clean)[0] - pair.attacked)
        rmse = {
            k: 255 * float(torch.cat([e.ravel() for e in v]).pow(2).mean().sqrt()) for k, v in errors.items()
        }
        shape = tuple(problem.pairs[0].clean.shape)
        print(
            f"{draw.name} case seed {draw.seed}, frames {shape}, {len(draw.heldout)} held-out pairs, selected "
            f"{report['extended']['effects']}, kwargs {kwargs}: calibration's held-out RMSE "
            f"{report['extended']['heldout_rmse']:.2f}, attack from calibrated.json {rmse['calibrated.json']:.2f}, "
            f"without its displacement {rmse['without its displacement']:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
