"""``shot_noise``: does the residual's variance grow with the light collected (photon shot noise), in linear light?

Photon shot noise is a property of the sensor, so it is modelled where the sensor counts photons: in *linear
light*, before the camera's tone curve. The tone curve compresses bright values, and under an sRGB curve the
shot-noise standard deviation in output grey levels is almost flat in the signal (``f'(x) sqrt(x) ~ x^-0.08``):
judged in output units, shot noise is invisible. Every residual (grey levels, output units) is therefore read at
its predicted signal ``x`` in linear light, with the local slope ``J = dy/dx`` of the tone curve (grey levels per
unit of linear light), and its variance is modelled as

    var(residual) = QUANTISATION_VARIANCE + detail * D + J^2 (read^2 + shot * x),

- ``read^2``: signal-independent sensor noise (read noise, dark current), constant in linear light;
- ``shot * x``: photon shot noise, Poisson, so its variance is proportional to the linear signal;
- ``QUANTISATION_VARIANCE``: the 8-bit rounding of the two frames of a pair, added in output units (known exactly);
- ``detail * D``: compression (JPEG) and resampling error, added in output units where the image has detail: ``D``
  is the local variance of the predicted frame (3x3), so flat regions carry none of it.

A value the attack computes after the sensor from other sensor values (the EM colour strip's mis-decoded rows:
red read from green times 2.5) carries their noise, weighted, and is read at them, not at the value it shows
(``noise_sample``'s ``sources``, from the frame model's ``noise_sources``).

Noise added after the tone curve in any other form (not a sensor's) is outside this model: under an sRGB curve a
constant output-unit noise has nearly the shape of photon noise (``J^2 x`` is almost flat) and would be read as it.

The tone curve is the fitted one when the mean model has one (``tone_shoulder``: the log-logistic shoulder of
calibration/tone.py; ``sensor_gamma``: a power law), otherwise sRGB (IEC 61966-2-1), the encoding of 8-bit camera
images when nothing else is stated; the report says which. Where no model fits the curve and the camera's curve has
a shoulder, the two terms are unidentifiable from single exposures (linearised with sRGB, the variance falls with
the signal): the assumption is stated, not hidden.

Noise cannot be predicted pixel by pixel, so it can never lower an RMSE: it is judged as a model of the residual's
*distribution*, by the mean Gaussian negative log-likelihood of residuals of pairs not used to fit it. The gain is
reported as a noise-scale ratio ``exp(NLL_read - NLL_shot)`` (1 = no gain; for two constant-variance models it is
exactly their ratio of standard deviations). Under an sRGB curve photon noise and the other terms differ little in
shape, so that ratio stays small (measured 1.03-1.05 with photon noise 90% of the variance) and says whether the
term is *there*; how *much* it matters is its share of the modelled residual variance. ``shot_noise`` is named
only if (1) the inner k-fold validation on the fit pairs shows a ratio above 1 (it predicts the variance of pairs
it was not fitted on better than without it), (2) the bootstrap interval (over fit pairs) of ``shot`` excludes its
null value 0, and (3) photon noise is the main part of the residual: at least ``SHOT_SHARE`` of its modelled
variance, averaged over the fit pairs' residuals, both in the model above and beside a multiplicative term
``J^2 gain^2 x^2`` (variance growing with the square of the light: a light that itself fluctuates by a share of
its level, as laser speckle does, or a mean model whose error is a share of the light; under the sRGB curve
``J^2 x`` is nearly flat while ``J^2 x^2`` rises with the signal, so the two are told apart), and (4) the model
follows the residual's variance across the signal (measured over modelled variance in the darkest quarter of the
signal against the brightest: its interval not above ``TREND_FACTOR``; read noise is the steepest fall any sensor
noise has under a curve, so a faster one means the curve compresses bright values more than the one assumed). A camera's photon noise is always present; it
is named as a cause of the residual only where it is what the residual mostly is. When (4) fails, the curve the
residuals were read through is not the camera's, and the report says "not identifiable" with why, instead of
dividing the variance between two terms that the frames cannot tell apart. And (5) the mean model leaves no
structure in the fit pairs' cross-fitted residuals (``structure.fit_items_structure``, the held-out structure
tests on fit pairs alone): a residual that still holds a mean effect the library has no name for is not sensor
noise, and its variance grows with the light wherever that effect does (the independent simulator's EM hum bars,
EM pixel slip and projector falloff were named photon noise, each beside the structure the report states:
docs/bench/session58.md). It runs after the mean model is selected, on that model's residuals, and changes no
prediction: it is reported under ``noise`` and in the findings, never as an effect of the written (mean) model.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import torch
from scipy import ndimage
from scipy.optimize import nnls

from lerobot_phantom.calibration.core import Fit, binned_rmse, selection_folds
from lerobot_phantom.calibration.identify import Interval, bootstrap
from lerobot_phantom.calibration.tone import shoulder_decode
from lerobot_phantom.transforms import physics

SAMPLES_PER_PAIR = 4000
CLIP_GUARD = 3.0  # grey levels: clipped pixels have no noise, so pixels near 0 or 255 say nothing about it
QUANTISATION_VARIANCE = 2.0 / 12.0  # grey levels^2: the residual of two frames each rounded to 8 bits
SHOT_SHARE = 0.5  # photon noise must be at least this share of the residual's modelled variance to be named
# the residual's variance may fall with the signal at most this factor faster than the noise model says (darkest
# vs brightest quarter, its interval above it): otherwise the tone curve it is read through is not the camera's.
# Measured on the independent simulator's EM truncation frames (docs/bench/camsim_session13.md): 0.75-1.02 under
# sRGB and power-law cameras, 2.1-4.5 under a filmic shoulder read as sRGB
TREND_FACTOR = 1.5
TERMS = ("detail", "read_var", "shot", "gain_var")


@dataclass
class NoiseSample:
    """Residuals of one or more pairs with where they sit on the tone curve and in the image's detail."""

    signal: np.ndarray  # predicted value, linear light in [0, 1]
    slope: np.ndarray  # tone-curve slope at that value: output grey levels per unit of linear light
    detail: np.ndarray  # local variance of the predicted frame around the value (grey levels^2)
    residual: np.ndarray  # measured - predicted, output grey levels

    @staticmethod
    def join(parts: list[NoiseSample]) -> NoiseSample:
        return NoiseSample(
            *(
                np.concatenate([getattr(p, k) for p in parts])
                for k in ("signal", "slope", "detail", "residual")
            )
        )

    def design(self, shot: bool, gain: bool = False) -> np.ndarray:
        """Columns of the variance model above quantisation: detail, read (J^2), with ``shot`` J^2 x, with
        ``gain`` J^2 x^2."""
        columns = [self.detail, self.slope**2]
        columns += [self.slope**2 * self.signal] if shot else []
        columns += [self.slope**2 * self.signal**2] if gain else []
        return np.stack(columns, axis=1)


def tone_curve(fit: Fit) -> float | dict | None:
    """What linearises the frames: the fitted shoulder curve (a dict of its parameters) if the mean model has
    ``tone_shoulder``, the fitted ``sensor_gamma`` (a number) if it has that, else None (sRGB)."""
    if "tone_shoulder" in fit.effects:
        return {
            k: float(fit.params[k])
            for k in ("shoulder", "shoulder_exponent", "gamma")
            if k in fit.params and (k != "gamma" or "sensor_gamma" in fit.effects)
        }
    return float(fit.params["gamma"]) if "sensor_gamma" in fit.effects and "gamma" in fit.params else None


def tone_curve_name(curve: float | dict | None) -> str:
    if curve is None:
        return "sRGB (IEC 61966-2-1; assumed: the model fits no tone curve)"
    if isinstance(curve, dict):
        return (
            f"log-logistic shoulder (fitted tone_shoulder: s {curve['shoulder']:.3g}, n "
            f"{curve['shoulder_exponent']:.3g}, gamma {curve.get('gamma', 1.0):.3g})"
        )
    return f"power law, gamma {curve:.3g} (fitted sensor_gamma)"


def linearise(grey: np.ndarray, curve: float | dict | None) -> tuple[np.ndarray, np.ndarray]:
    """Output grey levels -> (linear light in [0, 1], tone-curve slope dy/dx in grey levels per unit of light)."""
    encoded = torch.from_numpy(np.asarray(grey, np.float64) / 255.0).requires_grad_(True)
    if isinstance(curve, dict):
        linear = shoulder_decode(encoded, curve, curve.get("gamma"))
    else:
        linear = physics.decode(encoded, curve)
    (dx_dy,) = torch.autograd.grad(linear.sum(), encoded)
    return linear.detach().numpy(), 255.0 / np.maximum(dx_dy.numpy(), 1e-12)


def local_detail(image: np.ndarray) -> np.ndarray:
    """Per channel, the 3x3 local variance of an image (grey levels^2): where compression and resampling err."""
    mean = ndimage.uniform_filter(image, size=(1, 3, 3), mode="nearest")
    return np.maximum(ndimage.uniform_filter(image**2, size=(1, 3, 3), mode="nearest") - mean**2, 0.0)


def residual_samples(problem, fit: Fit, items: np.ndarray, seed: int) -> dict[int, NoiseSample]:
    """Per pair: residuals on a seeded pixel sample at their sources' signal in linear light (the problem's
    ``noise_sources``) and their local detail, clipped pixels left out."""
    rng = np.random.default_rng(seed)
    curve = tone_curve(fit)
    out = {}
    for i in items:
        with torch.no_grad():
            image = 255.0 * problem.predict_pair(fit, int(i)).numpy()
        measured = 255.0 * problem.pairs[int(i)].attacked.numpy()
        usable = np.flatnonzero(unclipped(image, measured))
        if len(usable) > SAMPLES_PER_PAIR:
            usable = np.sort(rng.choice(usable, SAMPLES_PER_PAIR, replace=False))
        out[int(i)] = noise_sample(image, measured, usable, curve, problem.noise_sources(fit, int(i)))
    return out


def unclipped(predicted: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """Where noise can be read (grey levels): clipped pixels have none, so a value is kept when its prediction is
    ``CLIP_GUARD`` from either end and the measured value is not at one."""
    return (predicted > CLIP_GUARD) & (predicted < 255.0 - CLIP_GUARD) & (measured > 0.5) & (measured < 254.5)


# Where a predicted frame's sensor noise comes from: sensor values (grey levels, the frame's shape) and the weight
# each carries into the frame's value there (a number or an array of the frame's shape). None: every value is its
# own source, weight 1.
NoiseSources = tuple[tuple[np.ndarray, np.ndarray | float], ...] | None


def noise_sample(
    predicted: np.ndarray,
    measured: np.ndarray,
    index: np.ndarray,
    curve: float | dict | None,
    sources: NoiseSources = None,
) -> NoiseSample:
    """The values at flat ``index`` of a predicted and a measured frame (grey levels, CHW) with their signal in
    linear light through ``curve``, its slope and the predicted frame's local detail.

    A value computed after the sensor as a weighted sum of sensor values (``sources``: a colour map that
    mis-decodes rows) carries their noise: variance ``sum w_k^2 J_k^2 (read + shot x_k)``. The sample's slope is
    then ``sqrt(sum w_k^2 J_k^2)`` and its signal the ``w_k^2 J_k^2``-weighted mean of the ``x_k``, which keeps the
    read and photon terms exact (the multiplicative term is read at that mean signal)."""
    values = predicted.ravel()[index]
    if sources is None:
        signal, slope = linearise(values, curve)
    else:
        spread, weighted_signal = np.zeros(len(index)), np.zeros(len(index))
        for frame, weight in sources:
            x, j = linearise(frame.ravel()[index], curve)
            share = np.broadcast_to(weight, predicted.shape).ravel()[index] ** 2 * j**2
            spread += share
            weighted_signal += share * x
        slope = np.sqrt(spread)
        signal = np.divide(weighted_signal, spread, out=np.zeros_like(spread), where=spread > 0)
    return NoiseSample(
        signal, slope, local_detail(predicted).ravel()[index], measured.ravel()[index] - values
    )


def model_variance(sample: NoiseSample, coef: dict[str, float]) -> np.ndarray:
    """Output-unit variance of every residual under the noise model with terms ``coef`` (missing terms = 0)."""
    terms = np.array([coef.get(k, 0.0) for k in TERMS])
    return np.maximum(QUANTISATION_VARIANCE + sample.design(True, True) @ terms, 1e-6)


def fit_variance(sample: NoiseSample, shot: bool, gain: bool = False) -> dict[str, float]:
    """Non-negative terms {detail, read_var, shot, gain_var} (read, shot and gain in linear light, full scale 1)
    maximising the Gaussian likelihood: iteratively reweighted non-negative least squares of ``residual^2 -
    quantisation`` on the model's columns (the weights follow var(r^2) = 2 sigma^4). Without ``shot`` or ``gain``
    that term is 0."""
    squared = sample.residual**2 - QUANTISATION_VARIANCE
    design = sample.design(shot, gain)
    names = [k for k in TERMS if (k != "shot" or shot) and (k != "gain_var" or gain)]
    coef = {k: 0.0 for k in TERMS}
    variance = np.full(len(squared), max(float(np.mean(sample.residual**2)), 1e-6))
    for _ in range(6):
        weight = 1.0 / variance
        values, _ = nnls(design * weight[:, None], squared * weight)
        coef.update(zip(names, values.tolist(), strict=True))
        variance = model_variance(sample, coef)
    return coef


def mean_nll(sample: NoiseSample, coef: dict[str, float]) -> float:
    variance = model_variance(sample, coef)
    return float(np.mean(0.5 * (np.log(2 * math.pi * variance) + sample.residual**2 / variance)))


def shot_share(sample: NoiseSample, coef: dict[str, float]) -> float:
    """Mean share of the modelled residual variance that is photon noise."""
    shot = sample.slope**2 * coef["shot"] * sample.signal
    return float(np.mean(shot / model_variance(sample, coef))) if len(shot) else 0.0


def variance_trend(sample: NoiseSample, coef: dict[str, float], bins: int = 4) -> float:
    """How much faster the residual's variance falls with the signal than the noise model says: the ratio of
    measured to modelled variance in the darkest ``1 / bins`` of the sample over that in the brightest (1: the
    model follows the variance across the signal)."""
    order = np.argsort(sample.signal)
    if len(order) < 2 * bins:
        return float("nan")
    darkest, brightest = order[: len(order) // bins], order[-(len(order) // bins) :]
    variance = model_variance(sample, coef)

    def ratio(index: np.ndarray) -> float:
        return float(np.mean(sample.residual[index] ** 2) / np.mean(variance[index]))

    bright = ratio(brightest)
    return ratio(darkest) / bright if bright > 0 else float("nan")  # no residual at all: nothing to follow


def select_shot_noise(
    problem,
    fit: Fit,
    fit_items: np.ndarray,
    heldout_items: np.ndarray,
    *,
    seed: int,
    margin: float,
    folds: int,
    draws: int = 200,
) -> dict:
    """Inner k-fold validation of ``shot_noise`` on the fit pairs, its bootstrap interval and share over fit pairs,
    then its held-out noise-scale ratio (pairs never used to fit it). ``margin`` is not used: see the module
    docstring (the likelihood ratio measures shape, the share measures size)."""
    samples = residual_samples(problem, fit, np.concatenate([fit_items, heldout_items]), seed + 3)

    def joined(items) -> NoiseSample:
        return NoiseSample.join([samples[int(i)] for i in items])

    validation_ratio = validation_noise_scale_ratio(joined, fit_items, folds=folds, seed=seed)
    if validation_ratio is None:
        return {"kept": False, "reasons": ["no unclipped pixels to judge the noise by"]}
    fitted, heldout = joined(fit_items), joined(heldout_items)
    curve = tone_curve(fit)
    without, with_shot = fit_variance(fitted, False), fit_variance(fitted, True)
    heldout_ratio = math.exp(mean_nll(heldout, without) - mean_nll(heldout, with_shot))

    def statistic(items: np.ndarray) -> dict[str, float]:
        sample = joined(items)
        coef = fit_variance(sample, True)
        beside_gain = fit_variance(sample, True, gain=True)
        return {
            **coef,
            "share": shot_share(sample, coef),
            "trend": variance_trend(sample, coef),
            "share_beside_gain": shot_share(sample, beside_gain),
            "gain_contrast": math.sqrt(beside_gain["gain_var"]),
        }

    intervals: dict[str, Interval] = bootstrap(
        statistic, np.asarray(fit_items), draws=draws, rng=np.random.default_rng([seed, 4])
    )
    reasons, curve_fails = shot_noise_reasons(validation_ratio, intervals, curve)
    return {
        "kept": not reasons,
        "status": "identified" if not reasons else "not identifiable" if curve_fails else "not identified",
        "reasons": reasons,
        "criterion": "Gaussian likelihood of the residuals with variance quantisation + detail D + J^2 (read^2 + "
        f"shot x) in linear light (J: tone-curve slope, D: local 3x3 variance) vs shot = 0, {folds}-fold "
        "validation on the fit pairs; named if the validation noise-scale ratio exp(NLL gain) is above 1, the "
        f"{100 * intervals['shot'].level:.0f}% bootstrap interval of shot (over fit pairs) excludes 0 and photon "
        f"noise is at least {SHOT_SHARE:.0%} of the modelled residual variance, also beside a multiplicative "
        "term (variance gain^2 x^2), and the mean model leaves no structure in the fit pairs' cross-fitted "
        "residuals (the held-out structure tests on fit pairs alone)",
        "tone_curve": tone_curve_name(curve),
        "validation_noise_scale_ratio": validation_ratio,
        "heldout_noise_scale_ratio": heldout_ratio,
        "shot_share": intervals["share"].as_dict(),
        "shot_share_beside_gain": intervals["share_beside_gain"].as_dict(),
        "variance_trend": intervals["trend"].as_dict(),
        "constant": {"read_noise_grey": 255.0 * math.sqrt(without["read_var"])},
        # linear-light grey levels (linear light x 255): read noise sd, shot variance per grey level of signal
        "shot_noise": {
            "read_noise_grey": 255.0 * math.sqrt(with_shot["read_var"]),
            "shot_gain_grey": 255.0 * with_shot["shot"],
            "detail_gain": with_shot["detail"],
        },
        # the relative sd of the light that a multiplicative term fits beside photon noise (residual of two frames)
        "multiplicative_relative_sd": intervals["gain_contrast"].as_dict(),
        "intervals": {
            "read_noise_grey": _scaled(intervals["read_var"], lambda v: 255.0 * math.sqrt(max(v, 0.0))),
            "shot_gain_grey": _scaled(intervals["shot"], lambda v: 255.0 * v),
        },
        "residual_vs_signal": binned_rmse(255.0 * heldout.signal, heldout.residual),
    }


def validation_noise_scale_ratio(
    joined: Callable[[np.ndarray], NoiseSample], fit_items: np.ndarray, *, folds: int, seed: int
) -> float | None:
    """exp(mean NLL without photon noise - with it) over k-fold validation pairs of the fit items; None when no
    fold has unclipped pixels on both sides."""
    validation = {"read": 0.0, "shot": 0.0}
    count = 0
    for train, val in selection_folds(fit_items, folds, seed):
        trained, scored = joined(train), joined(val)
        if len(trained.residual) == 0 or len(scored.residual) == 0:
            continue
        for name in validation:
            validation[name] += mean_nll(scored, fit_variance(trained, name == "shot")) * len(scored.residual)
        count += len(scored.residual)
    if count == 0:
        return None
    return math.exp((validation["read"] - validation["shot"]) / count)


def shot_noise_reasons(
    validation_ratio: float, intervals: Mapping[str, Interval], curve: float | dict | None
) -> tuple[list[str], bool]:
    """Why ``shot_noise`` is not named (the module docstring's conditions 1-4), and whether the tone curve is the
    reason (condition 4: then it is not identifiable rather than absent)."""
    reasons = []
    if not validation_ratio > 1.0:
        reasons.append(
            f"inner validation noise-scale ratio {validation_ratio:.3f} is not above 1: a variance growing with "
            "the linear signal predicts the residuals of unseen pairs no better than without it"
        )
    if not intervals["shot"].excludes(0.0):
        reasons.append(
            f"the interval of shot ({intervals['shot'].low:.3g}-{intervals['shot'].high:.3g}) includes the null "
            "value 0 (no photon noise)"
        )
    trend = intervals["trend"]
    # one-sided: read noise is the steepest fall with the signal any sensor noise has under a curve, so a faster
    # fall means the curve compresses bright values more than the one assumed (a shoulder). A slower one is
    # what photon noise is, so it says nothing against the curve
    curve_fails = trend.low > TREND_FACTOR
    if curve_fails:
        reasons.append(
            f"not identifiable: read through the {tone_curve_name(curve)} tone curve, the residual's variance "
            f"falls with the signal {trend.estimate:.2f}x "
            f"({100 * trend.level:.0f}% interval {trend.low:.2f}-{trend.high:.2f}; darkest vs brightest quarter, "
            f"relative to the noise model) beyond what any sensor noise can (named within {TREND_FACTOR:g}x): the "
            "camera's curve is not that one (a highlight shoulder compresses bright values more), and from frames "
            "that carry nothing about the curve, photon and read noise cannot be told apart"
        )
    if intervals["share"].estimate < SHOT_SHARE:
        reasons.append(
            f"photon noise is {intervals['share'].estimate:.0%} of the residual's modelled variance (named from "
            f"{SHOT_SHARE:.0%}): present, but not what the residual mostly is"
        )
    elif intervals["share_beside_gain"].estimate < SHOT_SHARE:
        contrast = intervals["gain_contrast"]
        reasons.append(
            f"the residual's variance grows with the square of the light, not in proportion to it: offered a "
            f"multiplicative term beside it (relative sd {contrast.estimate:.3g}, {100 * contrast.level:.0f}% "
            f"interval {contrast.low:.3g}-{contrast.high:.3g}), photon noise is "
            f"{intervals['share_beside_gain'].estimate:.0%} of the modelled variance (named from {SHOT_SHARE:.0%}): "
            "the light itself fluctuates from frame to frame (laser speckle, flicker) or the mean model errs in "
            "proportion to it, which is not a sensor's noise"
        )
    return reasons, curve_fails


def held_back_for_structure(noise: dict, structure: dict) -> dict:
    """``noise`` (a kept ``select_shot_noise`` result) not named when ``structure`` (the fit pairs' cross-fitted
    residual tests, condition 5 of the module docstring) finds structure left; the structure reading is recorded
    either way."""
    noise = {**noise, "fit_items_structure": structure}
    if not structure["structure_remains"]:
        return noise
    reason = (
        f"the mean model leaves structure in the fit pairs' residuals ({structure['summary']}): the residual is not "
        "sensor noise alone, so how its variance grows with the light says nothing about photon noise"
    )
    return {**noise, "kept": False, "status": "not identified", "reasons": [*noise["reasons"], reason]}


def _scaled(interval: Interval, f) -> dict:
    return {
        **interval.as_dict(),
        "estimate": f(interval.estimate),
        "low": f(interval.low),
        "high": f(interval.high),
    }


def apply_noise_finding(report: dict, fit: Fit, noise: dict) -> Fit:
    """Record the noise selection in ``report`` (``noise``, and a finding when ``shot_noise`` is named).

    The fit is returned unchanged: a noise model predicts nothing, so it is not an effect of the written model
    (``extended.effects`` and ``calibrated.json`` describe the mean model the transforms reproduce)."""
    report["noise"] = noise
    if not noise.get("kept"):
        return fit
    report["gain"]["noise_scale_ratio"] = noise["heldout_noise_scale_ratio"]
    shot = noise["intervals"]["shot_gain_grey"]
    report["findings"].append(
        {
            "effect": "shot_noise",
            "cause": "photon shot noise: in linear light the residual's variance grows in proportion to the light "
            "collected (variance = read^2 + shot x signal), not a constant read noise",
            "evidence": f"linearised with the {noise['tone_curve']} tone curve, the signal-dependent variance "
            f"model scores the residuals of held-out pairs with a noise-scale ratio "
            f"{noise['heldout_noise_scale_ratio']:.3f} (inner validation {noise['validation_noise_scale_ratio']:.3f}); "
            f"shot gain {shot['estimate']:.3g} linear-light grey levels^2 per linear-light grey level of signal "
            f"({100 * shot['level']:.0f}% interval {shot['low']:.3g}-{shot['high']:.3g}); it changes no "
            "prediction, so the RMSE is unchanged",
        }
    )
    return fit
