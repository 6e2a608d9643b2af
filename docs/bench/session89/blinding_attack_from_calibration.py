"""The laser blinding attack a calibration writes, fed the camera's own capture of the laser, against the fitted
frame model (session 88's ``blinding_attack_from_calibration.py``, with the capture reading's new home and two more
columns): a camsim blinding draw calibrated by ``lerobot-phantom-calibrate`` (its own selection), then
``make_attack("laser_blinding", intensity=s, calibration=OUT, pattern=<the pair's capture>)`` applied to each
held-out clean frame at that pair's intensity ``s``. RMSE in grey levels on the held-out pairs: the calibration's
own (report.json); the fit's prediction as session 88 scored it (``predict_pair``: under ``frame_exposure`` the
exposure node nearest the held-out frame, a registered figure) and its error expected over the exposure's prior
(``expected_squared_errors``: what a prediction made without the frame scores on average); the attack as a user
runs it (seed = pair index: one exposure draw, ``exposure_spread``), its root mean square over ``DRAWS`` draws
(seeds 0..DRAWS-1; the attack's counterpart of the expected figure), and the attack without the draw; and the attack
without the draw against the fit's prediction at the median exposure (the frame model with ``exposure_spread`` 0):
RMS and largest difference.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests:docs/bench/session88 python
docs/bench/session89/blinding_attack_from_calibration.py CASE:CASE_SEED...``
"""

from __future__ import annotations

import dataclasses
import sys

import torch
from calibrated_draws import calibrated_draws

DRAWS = 24


def rmse(values: list[torch.Tensor]) -> float:
    return 255 * float(torch.cat([v.ravel() for v in values]).pow(2).mean().sqrt())


def main() -> None:
    from lerobot_phantom.transforms.registry import make_attack

    for draw in calibrated_draws("laser_blinding", sys.argv[1:]):
        problem, report, kwargs = draw.problem, draw.report, draw.kwargs
        fit = draw.fit()
        median = dataclasses.replace(fit, params={**fit.params, "exposure_spread": 0.0})
        errors = {"fit, registered": [], "attack": [], "attack, no exposure draw": []}
        drawn_errors = []
        apart = []
        for i in draw.heldout:
            pair = problem.pairs[int(i)]
            capture = str(draw.folder / "pairs" / f"pattern_{int(i):03d}.png")  # camsim.write_pairs' names
            clean = pair.clean.unsqueeze(0).float()
            options = {"intensity": pair.intensity, "calibration": str(draw.out), "pattern": capture}
            drawn = make_attack("laser_blinding", seed=int(i), **options)(clean)[0].double()
            still = make_attack("laser_blinding", exposure_spread=0.0, **options)(clean)[0].double()
            errors["fit, registered"].append(problem.predict_pair(fit, int(i)) - pair.attacked)
            attack = make_attack(
                "laser_blinding", seed=0, **options
            )  # one generator: DRAWS exposures in turn
            drawn_errors += [attack(clean)[0].double() - pair.attacked for _ in range(DRAWS)]
            errors["attack"].append(drawn - pair.attacked)
            errors["attack, no exposure draw"].append(still - pair.attacked)
            model = (
                problem.predict_at_nodes(median, int(i))[0]
                if "frame_exposure" in fit.effects
                else problem.predict_pair(fit, int(i))
            )
            apart.append(still - model)
        largest = 255 * max(float(a.abs().max()) for a in apart)
        squared, counts = problem.expected_squared_errors(fit, draw.heldout)
        expected = float((squared.sum() / counts.sum()) ** 0.5)
        print(
            f"{draw.name} case seed {draw.seed}, {len(draw.heldout)} held-out pairs, selected "
            f"{report['extended']['effects']}, kwargs {kwargs}: calibration's held-out RMSE "
            f"{report['extended']['heldout_rmse']:.2f}; "
            + ", ".join(f"{name} {rmse(values):.2f}" for name, values in errors.items())
            + f"; fit, expected over the exposure prior {expected:.2f}, attack over {DRAWS} draws "
            f"{rmse(drawn_errors):.2f}"
            + f"; attack without the draw vs the model at the median exposure: RMS {rmse(apart):.2f}, largest "
            f"{largest:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
