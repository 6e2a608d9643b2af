"""Laser blinding frame pairs: the scene, a capture of the laser alone, and the blinded frame."""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param
from lerobot_phantom.calibration.frame_models.common import SENSOR_GAMMA, Pair, PixelProblem, flat_pixels
from lerobot_phantom.transforms import physics

BLINDING_EFFECTS = (
    Effect(
        "linear_light_saturation",
        "laser light adds to the scene's light in linear irradiance, the sum clips at the sensor's full well, and "
        "only then is the gamma curve applied - it does not blend the image with the pattern",
    ),
    Effect(
        "halo_power_law",
        "light scattered in the lens and on the sensor spreads glare far around the spot, falling off as a power "
        "of the distance (r^-k) rather than ending with the recorded pattern",
    ),
    Effect(
        "auto_exposure",
        "the camera's auto-exposure reacts to the injected light by lowering its gain, darkening the whole scene "
        "as the laser grows stronger",
    ),
    SENSOR_GAMMA,
)


def pattern_centre(pattern: torch.Tensor) -> tuple[float, float]:
    """(x, y) centroid of the brightest part of a laser pattern."""
    luminance = pattern.mean(0)
    mask = luminance >= luminance.max() - 0.05 * max(float(luminance.max() - luminance.min()), 1e-6)
    ys, xs = torch.nonzero(mask, as_tuple=True)
    return float(xs.double().mean()), float(ys.double().mean())


class BlindingFrames(PixelProblem):
    attack = "laser_blinding"
    base_model = "alpha blend of the scene and the laser pattern (the paper's laser blinding)"
    extended_model = "physical laser injection"
    candidates = BLINDING_EFFECTS

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        if any(p.pattern is None for p in pairs):
            raise ValueError(
                "laser_blinding frame pairs need a 'pattern' column: a capture of the laser alone (no scene)"
            )
        super().__init__(pairs, seed)
        self.centres = [pattern_centre(p.pattern) for p in pairs]
        # a fixed sample of each pattern's pixels: the mean light the exposure meter sees, for any tone curve
        probe_rng = np.random.default_rng(seed + 7)
        self.pattern_probe = torch.stack(
            [
                flat_pixels(p.pattern, torch.as_tensor(probe_rng.choice(p.height * p.width, 1024)))
                for p in pairs
            ]
        )
        self.colours = []
        for p in pairs:
            lin = physics.srgb_to_linear(p.pattern).reshape(3, -1)
            weight = lin.mean(0)
            colour = (lin * weight).sum(1) / weight.sum().clamp(min=1e-9)
            self.colours.append(colour / colour.max().clamp(min=1e-9))

    def centre(self, index: int) -> tuple[float, float]:
        return self.centres[index]

    def features(self, index: int, pixels: torch.Tensor | None) -> dict[str, torch.Tensor]:
        pair = self.pairs[index]
        ys, xs = torch.meshgrid(
            torch.arange(pair.height, dtype=torch.float64),
            torch.arange(pair.width, dtype=torch.float64),
            indexing="ij",
        )
        cx, cy = self.centres[index]
        radius = (torch.hypot(xs - cx, ys - cy) * pair.to_reference).reshape(-1, 1)
        if pixels is not None:
            radius = radius[pixels]
        n = len(radius)
        return {
            "scene": flat_pixels(pair.clean, pixels),
            "pattern": flat_pixels(pair.pattern, pixels),
            "radius": radius,
            "strength": torch.full((n, 1), pair.intensity, dtype=torch.float64),
            "pair": torch.full((n,), index, dtype=torch.long),
            "colour": self.colours[index].reshape(1, 3).expand(n, 3),
        }

    def param_specs(self, effects):
        specs = []
        if "linear_light_saturation" in effects:
            specs.append(Param("gain", 1.0, 0.0, 100.0, scale=1.0))
        else:
            specs.append(Param("alpha", 0.5, 0.0, 1.0, scale=0.3))
        if "halo_power_law" in effects:
            specs += [
                Param("halo_amplitude", 0.3, 0.0, 50.0, scale=0.3),
                Param("halo_exponent", 2.0, 0.2, 8.0, scale=1.0),
                Param("halo_scale_ref_px", 8.0, 0.3, 200.0, scale=8.0),
            ]
        if "auto_exposure" in effects:
            specs.append(Param("auto_exposure", 0.5, 0.0, 100.0, scale=0.5))
        if "sensor_gamma" in effects:
            specs.append(Param("gamma", 2.2, 0.3, 4.0, scale=1.0))
        return specs

    def null_values(self, effect: str) -> dict[str, float]:
        # the tone curve has no null here: the base composes encoded values, the linear model sRGB
        return {"halo_power_law": {"halo_amplitude": 0.0}, "auto_exposure": {"auto_exposure": 0.0}}.get(
            effect, {}
        )

    def predict_features(self, effects, params, f):
        if "sensor_gamma" in effects:
            gamma = params["gamma"]
        elif "linear_light_saturation" in effects:
            gamma = None  # sRGB
        else:
            gamma = 1.0  # the paper composes the encoded values
        scene, pattern = physics.decode(f["scene"], gamma), physics.decode(f["pattern"], gamma)
        s = f["strength"]
        if "linear_light_saturation" in effects:
            light, scene_weight = s * params["gain"] * pattern, 1.0
        else:
            opacity = (params["alpha"] * s).clamp(0.0, 1.0)
            light, scene_weight = opacity * pattern, 1.0 - opacity
        # the exposure meter sees the injected pattern light (not the scene), as physics.laser_injection
        pattern_mean = physics.decode(self.pattern_probe, gamma).mean(dim=(1, 2))[f["pair"]].unsqueeze(1)
        level = params["gain"] if "linear_light_saturation" in effects else params["alpha"]
        mean_light = level * s * pattern_mean
        if "halo_power_law" in effects:
            halo = physics.power_law_halo(
                f["radius"], params["halo_amplitude"], params["halo_exponent"], params["halo_scale_ref_px"]
            )
            light = light + s * halo * f["colour"]
        total = scene_weight * scene + light
        if "auto_exposure" in effects:
            total = total / (1.0 + params["auto_exposure"] * mean_light)
        return physics.encode(total.clamp(0.0, 1.0), gamma)

    def transform_kwargs(self, fit: Fit) -> dict:
        """``LaserBlinding`` options: the paper's alpha levels, or the physical model (``physics.laser_injection``)."""
        p, effects = fit.params, fit.effects
        if not effects:
            alpha = min(p["alpha"], 1.0)
            return {"levels": [0.0, alpha / 3, 2 * alpha / 3, alpha]}
        linear = "linear_light_saturation" in effects
        return {
            "model": "physical",
            "gain": p["gain"] if linear else p["alpha"],
            "glare_amplitude": p.get("halo_amplitude", 0.0),
            "glare_exponent": p.get("halo_exponent", 2.0),
            "glare_scale_ref_px": p.get("halo_scale_ref_px", 8.0),
            "auto_exposure": p.get("auto_exposure", 0.0),
            # tone curve the light was composed in: sRGB (None), fitted, or the encoded values (1.0)
            "gamma": p["gamma"] if "sensor_gamma" in effects else (None if linear else 1.0),
        }
