"""A camera tone curve with a highlight shoulder: a log-logistic (Naka-Rushton) response under a display gamma.

Physics. Film's characteristic curve and the "filmic" tone mapping of camera ISPs are sigmoids in log exposure:
a toe, a straight middle and a *shoulder* where ever more light adds ever less to the stored value, so that
highlights roll off instead of clipping. The log-logistic response ``R = E**n / (E**n + E_50**n)`` (the
Naka-Rushton law of photoreceptors, Hill's equation) is the standard one-knee form of such a curve. Normalised so
that the sensor's saturation (linear light ``x = 1``) stays the file's white and written as an exposure transfer
``h`` that reduces to the identity when the knee moves to infinite light:

    u = (1 + s) x**n / (1 + s x**n),     h(x) = u ** (1 / n),     pixel = h(x) ** (1 / gamma)

``s = E_50 ** -n`` >= 0 is the shoulder strength (``s = 0``: no shoulder, the curve is the power law of
``sensor_gamma``, or the identity without it), ``n`` > 0 the sharpness of the knee (large ``n``: almost a hard
clip at the knee; ``n`` -> 0: no knee at all, the power law ``x ** (1 / (1 + s))``, since ``x**n ~ 1 + n log x``),
``gamma`` the display exponent (1 when the model has no ``sensor_gamma``). So the curve is a gamma encoding too,
judged by its closest power law (``equivalent_power_gamma``), and on a power-law camera a fit drives ``n`` down
towards that limit (calibration/identify.py: causes a form implies; a simpler form in place of a richer one).
Its inverse is closed form, ``u = pixel ** (gamma n)``, ``x = (u / (1 + s - s u)) ** (1 / n)``, so every model
that composes light in linear irradiance (light projection: projector light adds to the ambient light) can decode
and re-encode through it. A pure power law cannot bend back below the straight line in log-log at the bright
end: fitted to a filmic camera it runs its exponent to the edge of its range and leaves the reflectance and
cross-talk effects that ride on the bright pixels unexplained (measured on the independent camera simulator:
docs/bench/camsim_session12.md, camsim_session18.md).
"""

from __future__ import annotations

from functools import partial

import numpy as np
import torch

from lerobot_phantom.calibration.core import Param
from lerobot_phantom.transforms import physics

SHOULDER_PARAMS = (
    # the knee's half-saturation light E_50 = s ** (-1 / n): s = 0.05 puts it ~20x above white (a barely bent
    # curve), s = 500 a few hundredths of white; beyond either end the curve is a power law or a hard clip
    Param("shoulder", 1.0, 0.0, 500.0, scale=3.0),
    Param("shoulder_exponent", 1.0, 0.25, 4.0, scale=0.5),
)
# ``sensor_gamma``'s power, decoding pixel values to linear light: every camera's encoding (sRGB, Rec. 709, log and
# filmic curves) compresses light, so the power is at least 1 (1: a linear camera, no gamma to name); a fit that
# wants less bends something other than a tone curve (camsim's white balance answering a projected cast fitted
# 0.657, docs/bench/session83.md). 4 is beyond any encoding in use
GAMMA_PARAM = Param("gamma", 2.2, 1.0, 4.0, scale=1.0)

# A camera's ISP mixes its raw channels with a colour correction matrix after the sensor (consumer cameras'
# matrices undo their colour filters' overlap: negative off-diagonals, rows summing to 1). One parameter per raw
# channel, ``ccm_<channel>``: that channel's light taken out of each of the other two (``physics.correction_matrix``);
# with the six off-diagonals free, a laser blinding calibration ran one to its bound and withdrew the term
# (docs/bench/session69/)
CHANNELS = ("red", "green", "blue")
CORRECTION_PARAMS = tuple(
    Param(
        f"ccm_{c}",
        0.1,
        0.0,
        1.0,
        scale=0.1,
        low_limit=f"the matrix takes none of the {c} channel's light out of the others",
    )
    for c in CHANNELS
)
CORRECTION_NULLS = {f"ccm_{c}": 0.0 for c in CHANNELS}


def correction_matrix(params: dict) -> torch.Tensor:
    """(3, 3) colour correction matrix of the takes ``params`` holds (``CORRECTION_PARAMS``)."""
    return physics.correction_matrix(
        torch.stack([torch.as_tensor(params[f"ccm_{c}"], dtype=torch.float64) for c in CHANNELS])
    )


# every parameter a fitted tone curve may have: ``sensor_gamma``'s power and the shoulder's two
TONE_PARAMS = ("gamma", *(p.name for p in SHOULDER_PARAMS))


def shoulder_curve(params: dict, gamma=None) -> physics.ShoulderCurve:
    """The shoulder ``params`` holds (``shoulder``, ``shoulder_exponent``; floats or tensors) under the display power
    law ``gamma`` (None: 1) as the curve the attacks compose light in (``physics.ShoulderCurve``)."""
    return physics.ShoulderCurve(
        params["shoulder"], params["shoulder_exponent"], 1.0 if gamma is None else gamma
    )


def shoulder_decode(encoded: torch.Tensor, params: dict, gamma=None) -> torch.Tensor:
    """Encoded pixel values in [0, 1] -> linear light in [0, 1] (the inverse of :func:`shoulder_encode`)."""
    return shoulder_curve(params, gamma).decode(encoded)


def shoulder_encode(linear: torch.Tensor, params: dict, gamma=None) -> torch.Tensor:
    """Linear light -> encoded pixel values (light beyond the sensor's saturation is clipped first)."""
    return shoulder_curve(params, gamma).encode(linear)


def equivalent_power_gamma(params: dict, gamma=None) -> float:
    """The power-law gamma closest to the fitted curve in encoded values over the whole range (least squares on a
    grid of 0.005 steps): the gamma encoding a shoulder implies, whose interval identification reads (the attack
    transforms take the shoulder itself, ``shoulder_kwargs``; until session 87 they took this gamma). The grid
    reaches 10: the shoulders fitted to filmic blurs (camsim's ACES curve on a 4x pre-gain, its knee far below the
    full well) are closest to gammas of 5.39-6.18, where a grid ending at 5 gave its end (docs/bench/session86.md)."""
    x = torch.linspace(0.0, 1.0, 257, dtype=torch.float64)
    curve = shoulder_encode(x, {k: float(v) for k, v in params.items()}, gamma).numpy()
    grid = np.linspace(0.3, 10.0, 1941)
    # identification calls this once per bootstrap draw: every gamma of the grid in one array
    errors = np.mean((x.numpy()[None, :] ** (1.0 / grid[:, None]) - curve) ** 2, axis=1)
    return float(grid[int(np.argmin(errors))])


def shoulder_kwargs(params: dict, gamma=None) -> dict[str, float | None]:
    """The attack transforms' options for the shoulder ``params`` holds under the display power law ``gamma``
    (None: 1): ``gamma``, ``shoulder``, ``shoulder_exponent`` (``physics.tone_options``)."""
    return {
        "gamma": None if gamma is None else float(gamma),
        "shoulder": float(params["shoulder"]),
        "shoulder_exponent": float(params["shoulder_exponent"]),
    }


def tone_nulls(effect: str) -> dict[str, float]:
    """Where a tone-curve form reduces to a model that composes the encoded values themselves: ``sensor_gamma`` at
    the power 1, ``tone_shoulder`` with its knee at infinite light (shoulder 0: the power law, the identity under the
    display gamma 1); {} for any other effect."""
    return {"sensor_gamma": {"gamma": 1.0}, "tone_shoulder": {"shoulder": 0.0}}.get(effect, {})


def implied_gamma_statistic(effect: str, implied: str, params: dict[str, float]) -> tuple[str, float, float]:
    """A shouldered curve's gamma encoding: the power-law gamma closest to it (null 1, linear pixel values)."""
    if (effect, implied) != ("tone_shoulder", "sensor_gamma"):
        raise ValueError(
            f"no statistic for {implied} implied by {effect}; valid: sensor_gamma by tone_shoulder"
        )
    return "equivalent_gamma", equivalent_power_gamma(params, params.get("gamma")), 1.0


def decode_encode(params: dict, shoulder: bool, gamma):
    """(decode, encode) between pixel values and linear light, clipped at the sensor's full well: the fitted
    shoulder of ``params`` under the display gamma ``gamma`` when ``shoulder``, else ``physics``' power law of
    exponent ``gamma`` (None: sRGB; 1: the encoded values themselves)."""
    tone = shoulder_curve(params, gamma) if shoulder else gamma
    return partial(physics.decode, gamma=tone), partial(physics.encode, gamma=tone)
