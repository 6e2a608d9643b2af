"""Why camsim's ``projection_crosstalk`` case loses ``albedo_modulation`` on filmic cameras: a factorial of in-sample
fits on each case's own frame pairs, rendered exactly as the test renders them.

Two things decode the light the model composes: the camera's tone curve (the clean and attacked frames) and the
curve that turns the recorded pattern into projector light. The package decodes both with the camera's fitted curve.
Camsim's projector emits ``frame ** 2.2`` and its filmic camera stores light through an ACES curve with a toe and a
shoulder, then sRGB. Each row fits additive light + cross-talk + light spread, without and with the reflectance term,
on all pairs (the package's pixel sample), with

* camera curve: ``gamma`` (the fitted ``sensor_gamma`` power law), ``shoulder`` (the fitted ``tone_shoulder``), or
  ``true`` (camsim's own curve, closed form; an oracle);
* pattern decoded by: ``camera`` (the camera's curve, as the package does), ``p2.2`` (the projector's true 2.2; an
  oracle), or ``pfit`` (a fitted power law of its own, ``projector_gamma``).

Printed per row: in-sample RMSE (grey levels) without and with the reflectance term, its floor (0: full
modulation, 2: none), and the tone parameters.

Usage: ``PYTHONPATH=. python docs/bench/session64/crosstalk_tone_factorial.py SEED...`` (master seeds).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.core import Param
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.projection import CROSSTALK_NAMES, tone_curve
from lerobot_phantom.transforms.physics import gaussian_spread

NAME = "projection_crosstalk"
BASE = ("additive_light", "channel_crosstalk", "light_spread")


def true_encode(linear: torch.Tensor, camera) -> torch.Tensor:
    """camsim.tone_curve in torch (differentiable in the light)."""
    x = linear.clamp(0.0, 1.0)
    if camera.tone == "filmic":

        def aces(v):
            return v * (2.51 * v + 0.03) / (v * (2.43 * v + 0.59) + 0.14)

        x = aces(4 * x) / aces(torch.tensor(4.0, dtype=x.dtype))
    elif camera.tone == "power":
        return x.clamp(min=1e-12) ** (1 / camera.tone_gamma)
    return torch.where(x <= 0.0031308, 12.92 * x, 1.055 * x.clamp(min=1e-12) ** (1 / 2.4) - 0.055)


def true_decode_table(camera):
    grid = torch.linspace(0.0, 1.0, 20001, dtype=torch.float64)
    encoded = true_encode(grid, camera).numpy()

    def decode(v: torch.Tensor) -> torch.Tensor:
        return torch.from_numpy(np.interp(v.numpy(), encoded, grid.numpy()))

    return decode


class Factorial(ProjectionFrames):
    def __init__(self, pairs, seed, camera_mode, pattern_mode, camera) -> None:
        super().__init__(pairs, seed)
        self.camera_mode, self.pattern_mode, self.camera = camera_mode, pattern_mode, camera
        self.true_decode = true_decode_table(camera)

    def param_specs(self, effects):
        specs = super().param_specs(effects)
        if self.pattern_mode == "pfit":
            specs.append(Param("projector_gamma", 2.2, 0.5, 4.0, scale=1.0))
        return specs

    def curves(self, effects, params):
        if self.camera_mode == "true":
            decode, encode = self.true_decode, (lambda v: true_encode(v, self.camera))
        else:
            decode, encode = tone_curve(effects, params)
        if self.pattern_mode == "camera":
            pattern = decode
        elif self.pattern_mode == "p2.2":
            pattern = lambda v: v.clamp(min=0.0) ** 2.2  # noqa: E731
        else:
            pattern = lambda v: v.clamp(min=1e-12) ** params["projector_gamma"]  # noqa: E731
        return decode, encode, pattern

    def predict_features(self, effects, params, feats):
        decode, encode, pattern_decode = self.curves(effects, params)
        surface = decode(feats["surface"])
        pairs = feats["pair"].tolist()
        rows = torch.split(feats["pixel"], feats["pixel_count"].tolist())
        light = []
        for k, i in enumerate(pairs):
            pair = self.pairs[i]
            spread = gaussian_spread(
                pattern_decode(pair.pattern)[None],
                params["spread_ref_px"] / torch.tensor([pair.to_reference], dtype=torch.float64),
                radius=self.spread_radius,
            ).flatten(2)[0]
            light.append(spread[:, rows[k]].T)
        light = torch.cat(light)
        matrix = torch.stack(
            [torch.as_tensor(params[n], dtype=surface.dtype) for n in CROSSTALK_NAMES]
        ).reshape(3, 3)
        light = feats["strength"] * (light @ matrix.T)
        if "albedo_modulation" in effects:
            light = light * (surface + params["reflectance_floor"]).clamp(min=0.0)
        return encode(surface + light).clamp(0.0, 1.0)


def main() -> None:
    seeds = [int(s) for s in sys.argv[1:]]
    import camsim

    for master, _sim, case, seed, rng, camera in case_draws(NAME, seeds):
        with tempfile.TemporaryDirectory() as scratch:
            camsim.write_pairs(Path(scratch) / "pairs", case.render(rng, camera))
            pairs = load_pairs(Path(scratch) / "pairs", max_side=256)  # the CLI's default working size
        print(f"master {master} case seed {seed}: tone {camera.tone}", flush=True)
        items = np.arange(len(pairs))
        for camera_mode, tone in (
            ("gamma", ("sensor_gamma",)),
            ("shoulder", ("tone_shoulder",)),
            ("true", ()),
        ):
            for pattern_mode in ("camera", "p2.2", "pfit"):
                problem = Factorial(pairs, 0, camera_mode, pattern_mode, camera)
                without = problem.fit(frozenset(BASE + tone), items)
                with_albedo = problem.fit(frozenset(BASE + tone + ("albedo_modulation",)), items)
                p = with_albedo.params
                tone_params = ", ".join(
                    f"{n} {p[n]:.2f} ({without.params[n]:.2f})"
                    for n in ("gamma", "shoulder", "shoulder_exponent", "projector_gamma")
                    if n in p
                )
                print(
                    f"  camera {camera_mode:8s} pattern {pattern_mode:6s} RMSE {problem.rmse(without, items):5.2f} "
                    f"-> {problem.rmse(with_albedo, items):5.2f} with reflectance, floor "
                    f"{p['reflectance_floor']:5.2f}; spread {p['spread_ref_px']:.2f}; {tone_params}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
