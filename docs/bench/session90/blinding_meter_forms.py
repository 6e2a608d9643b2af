"""The blinding model's meter in three forms, fitted on camsim's auto-exposure draws (the selection's own effects:
linear light, auto-exposure, frame exposure, tone curve), to see which reacts to the laser's light as camsim's
camera does and what that does to the model's prediction of an unseen frame:

* ``power``: the package's meter, ``k ** a`` with ``k`` the uniform clipped-light meter and ``a`` fitted;
* ``uniform``: the same meter with ``a`` fixed at 1 (no fitted power);
* ``centre``: ``a`` fixed at 1, the meter's pixels weighted by ``exp(-(dx^2 + dy^2) / (c^2 side^2))`` about the
  frame's centre (``dx``, ``dy`` as shares of the frame's width and height), ``c`` fitted: camsim's own centre-weighted
  form (0.6 there), a diagnostic of the cause, not a candidate for the library.

Per draw and form: the fit's RMSE over its fit pairs (latents registered), the held-out pairs' registered, predictive
and expected RMSE (the report's three figures), the fitted meter and spread, and at each held-out pair's registered
exposure the meter's reaction ``d log k / d log u`` to the laser's light (from ``exp(+-0.3)``), camsim's from the
noiseless re-render of ``blinding_exposure_sensitivity.py``; and what the spread costs: each form's expected RMSE
with the spread set to camsim's (the sample deviation of the fit pairs' true log exposures) and to 0 (the
prediction at the median exposure), beside camsim's own frames re-rendered without noise at the fit pairs' true
exposures (12 quantile nodes of their normal, as the model's) and at their mean: the floor no model without the
frame's exposure goes under.

``--luma`` (first): the ``luma`` form alone, the package's meter (its power fitted) reading each pixel's luminance
(Rec. 709 weights) where it reads the channel mean (session 90's lead from ``camsim_meter_parts.py``).
``--luma-channel-clip`` (first): the ``luma, channels clipped`` form alone, the luma meter with each channel
clipped before the weighting, as a meter reading the sensor's raw channels would (session 91).
``--every-pixel`` (first): the package's meter (``power`` alone) reads every pixel of a frame, not its sample of
``METER_PROBES`` drawn with replacement, in the calibration too.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests:docs/bench/session88:docs/bench/session90 python
docs/bench/session90/blinding_meter_forms.py [--every-pixel | --luma | --luma-channel-clip] CASE:CASE_SEED...``
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np
import torch
from blinding_exposure_sensitivity import GRID, predict, recorded_draws, rerendered

import lerobot_phantom.calibration.frame_models.laser_blinding as lb
from lerobot_phantom.calibration.core import Param
from lerobot_phantom.calibration.frame_models.laser_blinding import (
    METER_PROBES,
    BlindingFrames,
    exposure_nodes,
)
from lerobot_phantom.transforms import physics

STEP = 0.3
LUMA = (0.2126, 0.7152, 0.0722)


def weighted_exposure(total: torch.Tensor, scene: torch.Tensor, weight: torch.Tensor, steps: int = 12):
    """``physics.metered_exposure`` with the pixels weighted by ``weight`` (n, P)."""
    weight = weight / weight.sum(1, keepdim=True)
    target = (scene.clamp(max=1.0) * weight).sum(1)
    k = torch.ones(len(total), dtype=total.dtype)
    for _ in range(steps):
        lit = (k[:, None] * total < 1.0).to(total.dtype)
        reading = (torch.minimum(k[:, None] * total, torch.ones_like(total)) * weight).sum(1)
        slope = (total * lit * weight).sum(1).clamp(min=1e-9)
        k = (k - (reading - target) / slope).clamp(1e-4, 10.0)
    return k


class UniformMeter(BlindingFrames):
    def param_specs(self, effects):
        return [s for s in super().param_specs(effects) if s.name != "auto_exposure"]

    def exposure_factor(self, effects, params, decode, probes=None):
        f = self.probe_features if probes is None else probes
        total = self.compose(effects, params, f, decode).mean(1).reshape(-1, METER_PROBES)
        scene = self.scene_light(effects, params, f, decode).mean(1).reshape(-1, METER_PROBES)
        return physics.metered_exposure(total, scene)


class LumaMeter(BlindingFrames):
    """The package's meter (power fitted) reading each pixel's luminance (Rec. 709 weights of the linear channels)
    instead of its channel mean: a camera's auto-exposure statistic."""

    def exposure_factor(self, effects, params, decode, probes=None):
        f = self.probe_features if probes is None else probes
        luma = torch.tensor(LUMA, dtype=torch.float64)
        total = (self.compose(effects, params, f, decode) @ luma).reshape(-1, METER_PROBES)
        scene = (self.scene_light(effects, params, f, decode) @ luma).reshape(-1, METER_PROBES)
        return physics.metered_exposure(total, scene) ** params["auto_exposure"]


class LumaChannelClipMeter(BlindingFrames):
    """The package's meter (power fitted) reading the Rec. 709 luminance of each pixel's channels clipped one by
    one, ``sum_c w_c min(k total_c, 1)``: a meter fed by the sensor's raw channels, each saturating at its own
    photosite (session 91), where ``LumaMeter`` clips the luminance as a whole (camsim's statistic)."""

    def exposure_factor(self, effects, params, decode, probes=None):
        f = self.probe_features if probes is None else probes
        total = self.compose(effects, params, f, decode).reshape(-1, METER_PROBES * 3)
        scene = self.scene_light(effects, params, f, decode).reshape(-1, METER_PROBES * 3)
        weight = torch.tensor(LUMA, dtype=torch.float64).repeat(METER_PROBES).expand_as(total)
        return weighted_exposure(total, scene, weight) ** params["auto_exposure"]


class CentreMeter(UniformMeter):
    def param_specs(self, effects):
        return [*super().param_specs(effects), Param("meter_width", 0.6, 0.05, 5.0, scale=0.2)]

    def exposure_factor(self, effects, params, decode, probes=None):
        f = self.probe_features if probes is None else probes
        total = self.compose(effects, params, f, decode).mean(1).reshape(-1, METER_PROBES)
        scene = self.scene_light(effects, params, f, decode).mean(1).reshape(-1, METER_PROBES)
        pixels = torch.cat(self.probes) if probes is None else probes["pixel"]
        pair = self.pairs[0]  # camsim's frames share one size
        ys, xs = (pixels // pair.width).double(), (pixels % pair.width).double()
        dx, dy = (xs - pair.width / 2) / pair.width, (ys - pair.height / 2) / pair.height
        weight = torch.exp(-(dx**2 + dy**2) / params["meter_width"] ** 2).reshape(-1, METER_PROBES)
        return weighted_exposure(total, scene, weight)


def with_pixels(problem: BlindingFrames) -> None:
    """The probe features carry each probe's pixel index (CentreMeter's weights)."""
    problem.probe_features["pixel"] = torch.cat(problem.probes)


def meter_on_every_pixel() -> None:
    """The package's meter reads every pixel of a frame, not ``METER_PROBES`` drawn with replacement (frames of one
    size, as camsim's): the probes and their features are replaced once the problem is built."""
    original = lb.BlindingFrames.__init__

    def every_pixel(self, pairs, seed):
        original(self, pairs, seed)
        lb.METER_PROBES = pairs[0].height * pairs[0].width
        self.probes = [torch.arange(p.height * p.width) for p in pairs]
        self.probe_features = {
            k: torch.cat([self.features(i, self.probes[i])[k] for i in range(len(pairs))])
            for k in self.features(0, self.probes[0])
        }

    lb.BlindingFrames.__init__ = every_pixel


def rmse(squared_and_counts) -> float:
    squared, counts = squared_and_counts
    return float((np.sum(squared) / np.sum(counts)) ** 0.5)


def main() -> None:
    torch.set_num_threads(1)
    specs = sys.argv[1:]
    forms = (("power", BlindingFrames), ("uniform", UniformMeter), ("centre", CentreMeter))
    if specs[0] == "--every-pixel":
        meter_on_every_pixel()
        specs, forms = specs[1:], forms[:1]
    elif specs[0] == "--luma":
        specs, forms = specs[1:], (("luma", LumaMeter),)
    elif specs[0] == "--luma-channel-clip":
        specs, forms = specs[1:], (("luma, channels clipped", LumaChannelClipMeter),)
    for draw, calls, clean_calls, attacked_calls in recorded_draws(specs):
        effects = frozenset(draw.report["extended"]["effects"])
        print(f"{draw.name} case seed {draw.seed}: selected {sorted(effects)}, held-out {list(draw.heldout)}")
        if "frame_exposure" not in effects:
            print("  no frame_exposure selected: skipped")
            continue
        capture_exposure = calls[1][3]
        true_log_u = np.log([calls[k][3] / capture_exposure for k in clean_calls])
        fit_log_u = true_log_u[[int(i) for i in draw.fit_items]]
        true_spread = float(np.std(fit_log_u, ddof=1))
        nodes = np.log(exposure_nodes(true_spread).numpy()) + fit_log_u.mean()
        camsim_reaction, oracle, oracle_median = [], [], []
        for i in [int(i) for i in draw.heldout]:
            clean_irr, cam, _, clean_exposure = calls[clean_calls[i]]
            laser_irr = calls[attacked_calls[i]][0] - clean_irr
            up = rerendered(clean_irr, laser_irr, cam, clean_exposure, STEP)[1]
            down = rerendered(clean_irr, laser_irr, cam, clean_exposure, -STEP)[1]
            camsim_reaction.append(np.log(up / down) / (2 * STEP))
            target = draw.problem.pairs[i].attacked.numpy()
            moved = [
                rerendered(clean_irr, laser_irr, cam, clean_exposure, z - true_log_u[i])[0] for z in nodes
            ]
            oracle.append(np.mean([np.mean((m - target) ** 2) for m in moved]))
            at_mean = rerendered(clean_irr, laser_irr, cam, clean_exposure, fit_log_u.mean() - true_log_u[i])[
                0
            ]
            oracle_median.append(np.mean((at_mean - target) ** 2))
        heldout_u = ", ".join(f"{true_log_u[int(i)] - fit_log_u.mean():+.2f}" for i in draw.heldout)
        print(
            f"  camsim meter reaction d log k / d log u at the held-out pairs: {np.round(camsim_reaction, 3)}; "
            f"camsim, expected over the fit pairs' true exposures (spread {true_spread:.3f}, {len(nodes)} nodes, "
            f"noiseless re-render): {255 * np.mean(oracle) ** 0.5:.2f} (per pair "
            + ", ".join(f"{255 * o**0.5:.2f}" for o in oracle)
            + f"), at their mean exposure {255 * np.mean(oracle_median) ** 0.5:.2f}; held-out true log u from the "
            f"fit pairs' mean: {heldout_u}"
        )
        with_pixels(draw.problem)
        for name, form in forms:
            problem = draw.problem
            problem.__class__ = form
            fit = problem.fit(effects, draw.fit_items)
            fit_rmse = rmse(problem.registered_squared_errors(fit, draw.fit_items))
            figures = {
                kind: rmse(method(fit, draw.heldout))
                for kind, method in (
                    ("registered", problem.registered_squared_errors),
                    ("predictive", problem.item_squared_errors),
                    ("expected", problem.expected_squared_errors),
                )
            }
            squared, counts = problem.expected_squared_errors(fit, draw.heldout)
            per_pair = ", ".join(f"{v:.2f}" for v in np.sqrt(squared / counts))
            reaction = []
            for i in [int(i) for i in draw.heldout]:
                errors = [
                    255
                    * float((predict(problem, fit, i, g)[0] - problem.pairs[i].attacked).pow(2).mean().sqrt())
                    for g in GRID
                ]
                best = float(GRID[int(np.argmin(errors))])
                up, down = predict(problem, fit, i, best + STEP)[1], predict(problem, fit, i, best - STEP)[1]
                reaction.append(np.log(up / down) / (2 * STEP))
            shown = {
                k: round(float(v), 3)
                for k, v in fit.params.items()
                if k in ("auto_exposure", "meter_width", "exposure_spread", "log10_gain")
            }
            print(
                f"  {name}: {shown}; fit pairs {fit_rmse:.2f}; held-out "
                + ", ".join(f"{k} {v:.2f}" for k, v in figures.items())
                + f" (per pair {per_pair})"
                + f"; meter reaction {np.round(reaction, 3)}",
                flush=True,
            )
            for label, spread in (("camsim's true spread", true_spread), ("no spread (the median)", 0.0)):
                moved = dataclasses.replace(fit, params={**fit.params, "exposure_spread": spread})
                print(
                    f"    {name}, expected at {label}: {rmse(problem.expected_squared_errors(moved, draw.heldout)):.2f}"
                )
        draw.problem.__class__ = BlindingFrames


if __name__ == "__main__":
    main()
