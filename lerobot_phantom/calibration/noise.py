"""``shot_noise``: is the residual's variance signal-dependent (photon shot noise plus read noise)?

Noise cannot be predicted pixel by pixel, so it can never lower an RMSE; scoring it by RMSE would either never
keep it or keep it for the wrong reason. It is therefore judged as what it is, a model of the residual's
*distribution*: a Gaussian with variance ``read^2 + gain * signal`` (signal = the predicted pixel, grey levels)
against one constant variance, scored by the mean Gaussian negative log-likelihood of held-out residuals. The
likelihood gain is reported as a noise-scale ratio ``exp(NLL_constant - NLL_shot)`` (1 = no gain; for two
constant-variance models it is exactly their ratio of standard deviations), and ``shot_noise`` is kept only if
the same inner k-fold validation used for every other extension shows a ratio of at least ``1 / (1 - margin)``.
It runs after the mean model is selected, on that model's residuals, and changes no prediction.
"""

from __future__ import annotations

import math

import numpy as np
import torch
from scipy.optimize import nnls

from lerobot_phantom.calibration.core import Fit, binned_rmse, kfold

SAMPLES_PER_PAIR = 4000
CLIP_GUARD = 3.0  # grey levels: clipped pixels have no noise, so pixels near 0 or 255 say nothing about it


def residual_samples(
    problem, fit: Fit, items: np.ndarray, seed: int
) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per pair: (predicted signal, residual) in grey levels on a seeded pixel sample, clipped pixels left out."""
    rng = np.random.default_rng(seed)
    out = {}
    for i in items:
        pair = problem.pairs[int(i)]
        with torch.no_grad():
            predicted = 255.0 * problem.predict_pair(fit, int(i)).numpy().ravel()
        measured = 255.0 * pair.attacked.numpy().ravel()
        usable = np.flatnonzero(
            (predicted > CLIP_GUARD)
            & (predicted < 255.0 - CLIP_GUARD)
            & (measured > 0.5)
            & (measured < 254.5)
        )
        if len(usable) > SAMPLES_PER_PAIR:
            usable = np.sort(rng.choice(usable, SAMPLES_PER_PAIR, replace=False))
        out[int(i)] = (predicted[usable], measured[usable] - predicted[usable])
    return out


def fit_variance(signal: np.ndarray, residual: np.ndarray, shot: bool) -> tuple[float, float]:
    """(read variance, shot gain) maximising the Gaussian likelihood (iteratively reweighted non-negative least
    squares of ``residual^2`` on ``[1, signal]``; the weights follow var(r^2) = 2 sigma^4)."""
    squared = residual**2
    if not shot:
        return float(max(squared.mean(), 1e-6)), 0.0
    design = np.stack([np.ones_like(signal), signal], axis=1)
    variance = np.full_like(signal, max(squared.mean(), 1e-6))
    coef = np.array([variance[0], 0.0])
    for _ in range(4):
        weight = 1.0 / variance
        coef, _ = nnls(design * weight[:, None], squared * weight)
        variance = np.maximum(design @ coef, 1e-6)
    return float(max(coef[0], 1e-6)), float(coef[1])


def mean_nll(signal: np.ndarray, residual: np.ndarray, read_var: float, gain: float) -> float:
    variance = np.maximum(read_var + gain * signal, 1e-6)
    return float(np.mean(0.5 * (np.log(2 * math.pi * variance) + residual**2 / variance)))


def _join(samples, items) -> tuple[np.ndarray, np.ndarray]:
    parts = [samples[int(i)] for i in items]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def select_shot_noise(
    problem,
    fit: Fit,
    fit_items: np.ndarray,
    heldout_items: np.ndarray,
    *,
    seed: int,
    margin: float,
    folds: int,
) -> dict:
    """Inner k-fold selection of ``shot_noise`` on the fit pairs, then its held-out noise-scale ratio."""
    samples = residual_samples(problem, fit, np.concatenate([fit_items, heldout_items]), seed + 3)
    validation = {"constant": 0.0, "shot_noise": 0.0}
    count = 0
    for train, val in kfold(fit_items, folds, seed + 1):
        ts, tr = _join(samples, train)
        vs, vr = _join(samples, val)
        if len(ts) == 0 or len(vs) == 0:
            continue
        for name, shot in (("constant", False), ("shot_noise", True)):
            validation[name] += mean_nll(vs, vr, *fit_variance(ts, tr, shot)) * len(vs)
        count += len(vs)
    if count == 0:
        return {"kept": False, "reason": "no unclipped pixels to judge the noise by"}
    validation_ratio = math.exp((validation["constant"] - validation["shot_noise"]) / count)
    fs, fr = _join(samples, fit_items)
    hs, hr = _join(samples, heldout_items)
    constant, shot = fit_variance(fs, fr, False), fit_variance(fs, fr, True)
    heldout_ratio = math.exp(mean_nll(hs, hr, *constant) - mean_nll(hs, hr, *shot))
    return {
        "kept": validation_ratio >= 1.0 / (1.0 - margin),
        "criterion": "Gaussian negative log-likelihood of the residuals, variance read^2 + gain * signal vs "
        f"constant, {folds}-fold validation on the fit pairs; kept if exp(NLL gain) >= {1 / (1 - margin):.3f}",
        "validation_noise_scale_ratio": validation_ratio,
        "heldout_noise_scale_ratio": heldout_ratio,
        "constant": {"read_noise_grey": math.sqrt(constant[0])},
        "shot_noise": {"read_noise_grey": math.sqrt(shot[0]), "shot_gain_grey": shot[1]},
        "residual_vs_signal": binned_rmse(hs, hr),
    }


def apply_noise_finding(report: dict, fit: Fit, noise: dict) -> Fit:
    """Record the noise selection in ``report``; if ``shot_noise`` is kept, return the fit with it added."""
    report["noise"] = noise
    if not noise.get("kept"):
        return fit
    params = {
        **fit.params,
        "read_noise_grey": noise["shot_noise"]["read_noise_grey"],
        "shot_gain_grey": noise["shot_noise"]["shot_gain_grey"],
    }
    report["extended"]["effects"].append("shot_noise")
    report["extended"]["params"].update({k: params[k] for k in ("read_noise_grey", "shot_gain_grey")})
    report["gain"]["noise_scale_ratio"] = noise["heldout_noise_scale_ratio"]
    report["findings"].append(
        {
            "effect": "shot_noise",
            "cause": "photon shot noise: the residual's variance grows with the brightness of the pixel "
            "(variance = read^2 + gain x signal), not a constant read noise",
            "evidence": f"the signal-dependent variance model scores the residuals of held-out pairs with a "
            f"noise-scale ratio {noise['heldout_noise_scale_ratio']:.3f} (inner validation "
            f"{noise['validation_noise_scale_ratio']:.3f}); it changes no prediction, so the RMSE is unchanged",
        }
    )
    return Fit(fit.effects | {"shot_noise"}, params, fit.extra)
