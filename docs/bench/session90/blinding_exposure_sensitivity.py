"""Why the fitted blinding model predicts an unseen auto-exposed frame poorly (session 89's "Left"): on camsim's
auto-exposure draws, calibrated as a user calibrates them (``lerobot-phantom-calibrate``, its own selection), each
capture's exposure is recorded while the case renders, and three things are set side by side:

1. the latent: each pair's clean exposure over the laser capture's (``true log u``, centred over the fit pairs), the
   fit's registered ``frame_log_exposure`` on the fit pairs (centred), and for held-out pairs the factor on the
   model's median gain that fits the frame best on a fine grid (``best log u``);
2. sensitivity: how much the attacked frame changes when the laser's light in clean-frame units changes by
   ``exp(+-spread)`` (the fitted spread): in camsim, re-rendered without noise (Poisson and read noise off, the same
   meter, optics, ISP and JPEG) with the laser's irradiance scaled, against the frame at the true exposure; in the
   model, its prediction at ``best * exp(+-spread)`` against its prediction at ``best``. RMS in grey levels;
3. the meter: camsim's attacked exposure over the clean one's (the meter's factor) against the model's ``k ** a`` at
   the best factor.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests:docs/bench/session88 python
docs/bench/session90/blinding_exposure_sensitivity.py CASE:CASE_SEED...``
"""

from __future__ import annotations

import sys

import camsim
import numpy as np
import torch
from calibrated_draws import calibrated_draws

CAPTURE = camsim.capture  # the renderer's own, before main() records its calls
GRID = np.linspace(
    -1.5, 1.5, 61
)  # log factors on the model's median gain searched for a held-out frame's best


class Noiseless:
    """A generator stand-in for camsim.sensor: photons without shot noise, no read noise."""

    def poisson(self, lam):
        return np.asarray(lam, dtype=float)

    def normal(self, loc, scale, size):
        return np.zeros(size)


def predict(problem, fit, index: int, log_factor: float) -> torch.Tensor:
    """Pair ``index`` predicted with the laser's gain times ``exp(log_factor)`` (BlindingFrames.predict_at_nodes at one
    factor) and the model's meter factor ``k ** a`` there."""
    pair = problem.pairs[index]
    f = problem.features(index, None)
    probes = problem.probe_slots([index])
    factor = float(np.exp(log_factor))
    with torch.no_grad():
        flat = problem.predict_features(
            fit.effects,
            fit.params,
            {**f, "pair": torch.zeros_like(f["pair"]), "exposure": torch.full_like(f["exposure"], factor)},
            {**probes, "exposure": torch.full_like(probes["exposure"], factor)},
        )
        decode, _ = problem.memoised_tone_curve(fit.effects, fit.params)
        meter = problem.exposure_factor(
            fit.effects,
            fit.params,
            decode,
            {**probes, "exposure": torch.full_like(probes["exposure"], factor)},
        )
    return flat.T.reshape(3, pair.height, pair.width), float(meter[0])


def rerendered(
    clean_irr, laser_irr, cam, clean_exposure: float, log_factor: float
) -> tuple[np.ndarray, float]:
    """camsim's attacked frame without noise, the laser's irradiance times ``exp(log_factor)`` (encoded, CHW in
    [0, 1]), and its meter's factor (attacked exposure over the clean one's)."""
    frame, exposure = CAPTURE(clean_irr + np.exp(log_factor) * laser_irr, cam, Noiseless(), exposure=None)
    return camsim.encode(frame, cam).transpose(2, 0, 1) / 255.0, exposure / clean_exposure


def grey_rms(a, b) -> float:
    return 255 * float(
        (torch.as_tensor(a, dtype=torch.float64) - torch.as_tensor(b, dtype=torch.float64))
        .pow(2)
        .mean()
        .sqrt()
    )


def record_captures() -> list:
    """From now on every camsim capture call is appended to the returned list as (irradiance, camera, the exposure
    asked for or None when metered, the exposure used)."""
    calls = []

    def recorded(irradiance, cam, rng, **kwargs):
        out, exposure = CAPTURE(irradiance, cam, rng, **kwargs)
        calls.append((irradiance.copy(), cam, kwargs.get("exposure"), exposure))
        return out, exposure

    camsim.capture = recorded
    return calls


def recorded_draws(specs: list[str]):
    """Each draw ``CASE:CASE_SEED`` calibrated (``calibrated_draws``) with camsim's capture calls recorded while it
    renders (``record_captures``): (draw, calls, the clean frames' calls, the attacked frames' calls)."""
    calls = record_captures()
    for spec in specs:
        calls.clear()
        draw = next(calibrated_draws("laser_blinding", [spec]))
        # calls: clean 0, the laser capture (and its dark frame), attacked 0, then clean i, attacked i
        attacked_calls = [k for k, c in enumerate(calls) if c[2] is None]
        yield draw, calls, [0] + [k - 1 for k in attacked_calls[1:]], attacked_calls


def main() -> None:
    for draw, calls, clean_calls, attacked_calls in recorded_draws(sys.argv[1:]):
        problem, fit = draw.problem, draw.fit()
        capture_exposure = calls[1][3]
        true_log_u = np.log([calls[k][3] / capture_exposure for k in clean_calls])
        meter_true = [calls[a][3] / calls[c][3] for a, c in zip(attacked_calls, clean_calls, strict=True)]
        spread = fit.params.get("exposure_spread", 0.0)
        print(
            f"{draw.name} case seed {draw.seed}: selected {sorted(fit.effects)}, meter power "
            f"{fit.params.get('auto_exposure', 0.0):.3f}, spread {spread:.3f}, held-out {list(draw.heldout)}"
        )
        fit_items = [int(i) for i in draw.fit_items]
        centre = true_log_u[fit_items].mean()
        if "frame_exposure" in fit.effects:
            registered = fit.extra["frame_log_exposure"]
            print(
                "  fit pairs: true log u (centred) "
                + " ".join(f"{true_log_u[i] - centre:+.2f}" for i in fit_items)
            )
            print("             registered          " + " ".join(f"{r:+.2f}" for r in registered))
            print(
                f"             correlation {np.corrcoef(true_log_u[fit_items], registered)[0, 1]:.3f}, true sd "
                f"{np.std(true_log_u[fit_items], ddof=1):.3f}"
            )
        for i in [int(i) for i in draw.heldout]:
            pair = problem.pairs[i]
            target = pair.attacked
            errors = [grey_rms(predict(problem, fit, i, g)[0], target) for g in GRID]
            best = float(GRID[int(np.argmin(errors))])
            at_best, meter_model = predict(problem, fit, i, best)
            clean_irr, cam, _, clean_exposure = calls[clean_calls[i]]
            laser_irr = calls[attacked_calls[i]][0] - clean_irr
            truth_now, _ = rerendered(clean_irr, laser_irr, cam, clean_exposure, 0.0)
            line = (
                f"  held-out {i}: true log u {true_log_u[i] - centre:+.2f}, best log u {best:+.2f} (RMSE "
                f"{min(errors):.2f}; at the median {errors[len(GRID) // 2]:.2f}); noiseless camsim vs frame "
                f"{grey_rms(truth_now, target):.2f}; meter camsim {meter_true[i]:.3f}, model {meter_model:.3f}"
            )
            for sign in (-1, 1):
                step = sign * spread
                moved, meter_moved = rerendered(clean_irr, laser_irr, cam, clean_exposure, step)
                predicted, model_moved = predict(problem, fit, i, best + step)
                line += (
                    f"; laser x exp({step:+.2f}): camsim moves {grey_rms(moved, truth_now):.2f} (meter x "
                    f"{meter_moved / meter_true[i]:.3f}), model {grey_rms(predicted, at_best):.2f} (meter x "
                    f"{model_moved / meter_model:.3f})"
                )
            print(line, flush=True)


if __name__ == "__main__":
    main()
