"""Ultrasound blur frame pairs: a clean frame and the frame blurred by the resonating stabiliser."""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param, fit_least_squares
from lerobot_phantom.calibration.frame_models.common import SENSOR_GAMMA, FrameProblem, Pair
from lerobot_phantom.transforms import physics

BLUR_EFFECTS = (
    Effect(
        "sinusoidal_motion",
        "ultrasound makes the gyroscope resonate, so the stabiliser moves the image sinusoidally: the motion "
        "dwells at its turning points, an arcsine-weighted blur path instead of a uniform line average",
    ),
    SENSOR_GAMMA,
)


class BlurFrames(FrameProblem):
    attack = "ultrasound_blur"
    base_model = "uniform line average along a fitted displacement (the paper's ultrasound blur, linear part)"
    extended_model = "resonant (sinusoidal) motion blur"
    candidates = BLUR_EFFECTS
    taps = 17

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        self._grid_starts: dict[frozenset[str], list[dict[str, float]]] = {}

    def param_specs(self, effects):
        specs = [
            Param("dx_ref_px", 0.0, -64.0, 64.0, scale=4.0),
            Param("dy_ref_px", 0.0, -64.0, 64.0, scale=4.0),
        ]
        if "sensor_gamma" in effects:
            specs.append(Param("gamma", 2.2, 0.3, 4.0, scale=1.0))
        return specs

    def null_values(self, effect: str) -> dict[str, float]:
        return {"gamma": 1.0} if effect == "sensor_gamma" else {}  # the base blurs the encoded values

    def blur(self, effects, params, index: int) -> torch.Tensor:
        pair = self.pairs[index]
        path = "sinusoidal" if "sinusoidal_motion" in effects else "uniform"
        offsets = physics.blur_path_offsets(path, self.taps, dtype=torch.float64)
        gamma = params.get("gamma") if "sensor_gamma" in effects else 1.0
        x = physics.decode(pair.clean.unsqueeze(0), gamma)
        scale = pair.intensity / pair.to_reference
        dx = torch.as_tensor(params["dx_ref_px"] * scale, dtype=torch.float64)
        dy = torch.as_tensor(params["dy_ref_px"] * scale, dtype=torch.float64)
        return physics.encode(physics.line_blur(x, dx, dy, offsets), gamma)[0]

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        with torch.no_grad():
            return self.blur(fit.effects, fit.params, index)

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        def residuals(p):
            return torch.cat(
                [(self.blur(effects, p, int(i)) - self.pairs[int(i)].attacked).ravel() for i in items]
            )

        # the blur displacement is far from convex (textures alias): start from the best points of a grid of
        # directions and lengths, scored on a few pairs, besides any nested model's fit
        grid = []
        for length in (2.0, 5.0, 10.0, 20.0, 35.0, 55.0):
            for angle in np.arange(12) * np.pi / 12:
                grid.append({"dx_ref_px": length * np.cos(angle), "dy_ref_px": length * np.sin(angle)})
        base = {"gamma": torch.tensor(2.2, dtype=torch.float64)} if "sensor_gamma" in effects else {}
        probe = items[:3]

        def probe_cost(params):
            return sum(
                float(((self.blur(effects, params, int(i)) - self.pairs[int(i)].attacked) ** 2).sum())
                for i in probe
            )

        # the grid only picks starting points: scored once per model (on pairs of the fit split, which every
        # call during selection draws from), then reused by the folds
        if effects not in self._grid_starts:
            with torch.no_grad():
                costs = [
                    probe_cost({**base, **{k: torch.tensor(v, dtype=torch.float64) for k, v in g.items()}})
                    for g in grid
                ]
            self._grid_starts[effects] = [grid[int(k)] for k in np.argsort(costs)[:2]]
        best = self._grid_starts[effects]
        params = fit_least_squares(
            self.param_specs(effects),
            residuals,
            warm=best[0] if start is None else start.params,
            starts=[best[1] if start is None else best[0]],
            autodiff=False,
            max_nfev=30,
        )
        return Fit(effects, params)

    def transform_kwargs(self, fit: Fit) -> dict:
        """``UltrasoundBlur`` options: the blur path (camera physics); its length stays the attack's setting."""
        kwargs: dict = {}
        if "sinusoidal_motion" in fit.effects:
            kwargs["path"] = "sinusoidal"
        if "sensor_gamma" in fit.effects:
            kwargs["gamma"] = fit.params["gamma"]
        return kwargs

    def derived(self, fit: Fit) -> dict:
        dx, dy = fit.params["dx_ref_px"], fit.params["dy_ref_px"]
        return {
            "blur_length_ref_px_at_intensity_1": float(np.hypot(dx, dy)),
            "direction_deg": float(np.degrees(np.arctan2(dy, dx))),
        }
