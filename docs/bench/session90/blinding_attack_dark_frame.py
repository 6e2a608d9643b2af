"""The laser blinding attack a calibration writes, fed the pair's capture with and without its dark frame
(``pattern_dark``, session 90), against the fitted frame model, which reads the dark frame: camsim's
``blinding_halo_dark_frame`` draws (glare, a dark room whose light varies, the capture repeated with the laser off)
calibrated by ``lerobot-phantom-calibrate`` (its own selection), then ``make_attack("laser_blinding", intensity=s,
calibration=OUT, pattern=CAPTURE[, pattern_dark=DARK])`` on each held-out clean frame. RMS in grey levels over the
held-out pairs: the attack against the fit's prediction (``predict_pair``; draws whose selection holds
``frame_exposure`` are skipped, their attack draws an exposure) and against the held-out frames, beside the fit's.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests:docs/bench/session88 python
docs/bench/session90/blinding_attack_dark_frame.py CASE_SEED...``
"""

from __future__ import annotations

import sys

import torch
from calibrated_draws import calibrated_draws


def rms(values: list[torch.Tensor]) -> float:
    return 255 * float(torch.cat([v.ravel() for v in values]).pow(2).mean().sqrt())


def main() -> None:
    from lerobot_phantom.transforms.registry import make_attack

    for draw in calibrated_draws("laser_blinding", [f"blinding_halo_dark_frame:{s}" for s in sys.argv[1:]]):
        problem, fit = draw.problem, draw.fit()
        selected = sorted(fit.effects)
        if "frame_exposure" in fit.effects:
            print(f"case seed {draw.seed}: selected {selected}: skipped (the attack draws an exposure)")
            continue
        apart = {"capture alone": [], "capture and dark frame": []}
        to_frames = {name: [] for name in apart}
        fitted = []
        for i in [int(i) for i in draw.heldout]:
            pair = problem.pairs[i]
            options = {
                "intensity": pair.intensity,
                "calibration": str(draw.out),
                "pattern": str(draw.folder / "pairs" / f"pattern_{i:03d}.png"),  # camsim.write_pairs' names
            }
            dark = {"pattern_dark": str(draw.folder / "pairs" / f"pattern_dark_{i:03d}.png")}
            model = problem.predict_pair(fit, i)
            fitted.append(model - pair.attacked)
            clean = pair.clean.unsqueeze(0).float()
            for name, extra in (("capture alone", {}), ("capture and dark frame", dark)):
                attacked = make_attack("laser_blinding", **options, **extra)(clean)[0].double()
                apart[name].append(attacked - model)
                to_frames[name].append(attacked - pair.attacked)
        print(
            f"case seed {draw.seed}: selected {selected}, {len(draw.heldout)} held-out pairs; fit's held-out RMSE "
            f"{rms(fitted):.2f}; "
            + "; ".join(
                f"attack, {name}: {rms(apart[name]):.2f} RMS from the fit (largest "
                f"{255 * max(float(a.abs().max()) for a in apart[name]):.2f}), held-out RMSE {rms(to_frames[name]):.2f}"
                for name in apart
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
