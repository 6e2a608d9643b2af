"""Frame pairs -> any camera attack: a folder with ``pairs.csv`` (clean, attacked[, pattern][, intensity], ...).

Items are whole image pairs (held-out pairs are never seen while fitting). Frames are resized so that their
longer side is at most ``max_side`` pixels (area averaging); pixel-sized parameters are reported on the package's
256-pixel reference scale.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import torch
from PIL import Image

from lerobot_phantom.calibration.core import Effect, Fit, Param, Problem, binned_rmse, fit_least_squares
from lerobot_phantom.calibration.projection import (
    EFFECTS as PROJECTION_EFFECTS,
)
from lerobot_phantom.calibration.projection import (
    projection_kwargs,
    projection_predict,
    projection_specs,
    projection_warm,
)
from lerobot_phantom.transforms import physics

REFERENCE_SIZE = 256

SENSOR_GAMMA = Effect(
    "sensor_gamma",
    "the camera composes light in linear irradiance but stores gamma-encoded values, so effects that add or "
    "average light are wrong when applied to the encoded pixel values",
)
SHOT_NOISE = Effect(
    "shot_noise",
    "photon shot noise: the residual's variance grows with the brightness of the pixel, not a constant read noise",
)


def load_rgb(path: Path, size: tuple[int, int] | None = None, max_side: int | None = None) -> torch.Tensor:
    """An image file -> float64 (3, H, W) in [0, 1] (alpha dropped), resized to ``size`` (W, H) or ``max_side``."""
    if not path.is_file():
        raise FileNotFoundError(f"image not found: {path}")
    image = Image.open(path).convert("RGB")
    if size is None and max_side is not None and max(image.size) > max_side:
        factor = max_side / max(image.size)
        size = (max(1, round(image.size[0] * factor)), max(1, round(image.size[1] * factor)))
    if size is not None and image.size != tuple(size):
        image = image.resize(tuple(size), Image.Resampling.BOX)
    return torch.from_numpy(np.asarray(image, dtype=np.float64) / 255.0).permute(2, 0, 1).contiguous()


@dataclass
class Pair:
    name: str
    clean: torch.Tensor
    attacked: torch.Tensor
    pattern: torch.Tensor | None
    intensity: float
    settings: dict = field(default_factory=dict)
    original_size: tuple[int, int] = (0, 0)  # (W, H) before resizing

    @property
    def height(self) -> int:
        return self.clean.shape[1]

    @property
    def width(self) -> int:
        return self.clean.shape[2]

    @property
    def to_reference(self) -> float:
        """Pixels at this working size -> pixels at the 256-pixel reference scale."""
        return REFERENCE_SIZE / max(self.height, self.width)


def load_pairs(folder: Path, *, max_side: int) -> list[Pair]:
    table_path = folder / "pairs.csv"
    if not table_path.is_file():
        raise FileNotFoundError(
            f"{folder} has no pairs.csv (columns clean,attacked[,pattern][,intensity],...)"
        )
    table = pd.read_csv(table_path)
    for column in ("clean", "attacked"):
        if column not in table.columns:
            raise ValueError(
                f"{table_path} lacks column {column!r}; needs clean,attacked[,pattern][,intensity]"
            )
    pairs = []
    for i, row in table.iterrows():
        clean_path = folder / str(row["clean"])
        with Image.open(clean_path) as probe:
            original = probe.size
        clean = load_rgb(clean_path, max_side=max_side)
        size = (clean.shape[2], clean.shape[1])
        with Image.open(folder / str(row["attacked"])) as probe:
            if probe.size != original:
                raise ValueError(
                    f"pair {i}: clean {row['clean']} is {original} but attacked {row['attacked']} is {probe.size}"
                )
        attacked = load_rgb(folder / str(row["attacked"]), size=size)
        pattern = None
        if "pattern" in table.columns and isinstance(row["pattern"], str) and row["pattern"]:
            pattern = load_rgb(folder / row["pattern"], size=size)
        intensity = 1.0
        if "intensity" in table.columns and not pd.isna(row["intensity"]):
            intensity = float(row["intensity"])
            if not 0.0 <= intensity <= 1.0:
                raise ValueError(f"pair {i}: intensity must lie in [0, 1], got {intensity}")
        extra = {k: row[k] for k in table.columns if k not in ("clean", "attacked", "pattern", "intensity")}
        pairs.append(Pair(str(row["attacked"]), clean, attacked, pattern, intensity, extra, original))
    if len(pairs) < 2:
        raise ValueError(
            f"{table_path}: need at least 2 pairs (one to fit, one to hold out), got {len(pairs)}"
        )
    return pairs


class FrameProblem(Problem):
    """Shared machinery: per-pair prediction, squared errors, residual analysis and figures."""

    input_kind = "frame_pairs"
    units = "grey levels (0-255)"

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        self.pairs = pairs
        self.seed = seed

    @property
    def n_items(self) -> int:
        return len(self.pairs)

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        raise NotImplementedError

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        total, count = 0.0, 0
        for i in items:
            residual = 255.0 * (self.predict_pair(fit, int(i)) - self.pairs[int(i)].attacked)
            total += float((residual**2).sum())
            count += residual.numel()
        return total, count

    def analyse(self, fit: Fit, items: np.ndarray) -> dict:
        per_pair_s, per_pair_rmse = [], []
        channel, row, radius, brightness, res_all = [], [], [], [], []
        spectrum_r, spectrum_p = [], []
        for i in items:
            pair = self.pairs[int(i)]
            residual = (255.0 * (self.predict_pair(fit, int(i)) - pair.attacked)).numpy()
            per_pair_s.append(pair.intensity)
            per_pair_rmse.append(float(np.sqrt(np.mean(residual**2))))
            _, height, width = residual.shape
            ys, xs = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
            channel.append(np.broadcast_to(np.arange(3)[:, None, None], residual.shape).ravel())
            row.append(np.broadcast_to(ys / max(height - 1, 1), residual.shape).ravel())
            centre = self.centre(int(i))
            r = np.hypot(xs - centre[0], ys - centre[1]) * pair.to_reference
            radius.append(np.broadcast_to(r, residual.shape).ravel())
            brightness.append(pair.clean.numpy().ravel() * 255)
            res_all.append(residual.ravel())
            power = np.abs(np.fft.fft2(residual.mean(0))) ** 2
            fy = np.fft.fftfreq(height)[:, None]
            fx = np.fft.fftfreq(width)[None, :]
            spectrum_r.append(np.hypot(fx, fy).ravel())
            spectrum_p.append(power.ravel() / power.size)
        res = np.concatenate(res_all)
        freq = np.concatenate(spectrum_r)
        power = np.concatenate(spectrum_p)
        edges = np.array([0, 0.02, 0.05, 0.1, 0.2, 0.35, 0.75])
        band = np.clip(np.searchsorted(edges, freq, side="right") - 1, 0, len(edges) - 2)
        return {
            "intensity": {"x": per_pair_s, "rmse": per_pair_rmse},
            "channel": binned_rmse(np.concatenate(channel), res),
            "row_position": binned_rmse(np.concatenate(row), res),
            "radius_ref_px": binned_rmse(np.concatenate(radius), res),
            "clean_brightness": binned_rmse(np.concatenate(brightness), res),
            "spatial_frequency": {
                "x": [float(0.5 * (edges[k] + edges[k + 1])) for k in range(len(edges) - 1)],
                "rmse": [
                    float(np.sqrt(power[band == k].sum() / max(len(items), 1))) for k in range(len(edges) - 1)
                ],
            },
        }

    def centre(self, index: int) -> tuple[float, float]:
        pair = self.pairs[index]
        return (pair.width - 1) / 2.0, (pair.height - 1) / 2.0

    def evidence(self, effect: str, before: Fit, after: Fit, items: np.ndarray) -> str:
        b = math.sqrt(self.squared_errors(before, items)[0] / max(self.squared_errors(before, items)[1], 1))
        a = math.sqrt(self.squared_errors(after, items)[0] / max(self.squared_errors(after, items)[1], 1))
        return f"on the fitting pairs adding {effect} takes the RMSE from {b:.2f} to {a:.2f} grey levels"

    def figures(self, base: Fit, extended: Fit, items: np.ndarray, out_dir: Path) -> list[str]:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        index = int(items[0])
        pair = self.pairs[index]
        panels = [
            ("clean", pair.clean),
            ("measured attacked", pair.attacked),
            ("base prediction", self.predict_pair(base, index)),
            ("extended prediction", self.predict_pair(extended, index)),
        ]
        fig, axes = plt.subplots(2, 3, figsize=(12, 7))
        for ax, (title, image) in zip(axes.ravel()[:4], panels, strict=True):
            ax.imshow(image.permute(1, 2, 0).clamp(0, 1).numpy())
            ax.set_title(title)
        for ax, (title, fit) in zip(axes.ravel()[4:], (("base", base), ("extended", extended)), strict=True):
            residual = (255.0 * (self.predict_pair(fit, index) - pair.attacked)).abs().mean(0).numpy()
            shown = ax.imshow(residual, cmap="magma", vmin=0)
            ax.set_title(f"|{title} residual| (grey levels), RMSE {np.sqrt(np.mean(residual**2)):.1f}")
            fig.colorbar(shown, ax=ax, fraction=0.046)
        for ax in axes.ravel():
            ax.axis("off")
        fig.suptitle(f"held-out pair {pair.name}")
        fig.tight_layout()
        path = out_dir / "residual_maps.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        return [path.name]


def _pixel_sample(pair: Pair, count: int, rng: np.random.Generator) -> np.ndarray:
    n = pair.height * pair.width
    return np.sort(rng.choice(n, min(count, n), replace=False))


class PixelProblem(FrameProblem):
    """Attacks that act pixel by pixel given per-pixel features; fits use a seeded sample of pixels per pair."""

    pixels_per_pair = 800

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        rng = np.random.default_rng(seed)
        self.samples = [torch.as_tensor(_pixel_sample(p, self.pixels_per_pair, rng)) for p in pairs]

    def features(self, index: int, pixels: torch.Tensor | None) -> dict[str, torch.Tensor]:
        raise NotImplementedError

    def predict_features(self, effects, params, feats: dict[str, torch.Tensor]) -> torch.Tensor:
        raise NotImplementedError

    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        raise NotImplementedError

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        pair = self.pairs[index]
        with torch.no_grad():
            flat = self.predict_features(fit.effects, fit.params, self.features(index, None))
        return flat.T.reshape(3, pair.height, pair.width)

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        feats = [self.features(int(i), self.samples[int(i)]) for i in items]
        stacked = {k: torch.cat([f[k] for f in feats]) for k in feats[0]}
        target = torch.cat(
            [self.pairs[int(i)].attacked.reshape(3, -1)[:, self.samples[int(i)]].T for i in items]
        )
        params = fit_least_squares(
            self.param_specs(effects),
            lambda p: (self.predict_features(effects, p, stacked) - target).ravel(),
            warm=self.warm(start, effects),
            starts=[{}] if start is not None else [],  # also from the defaults: saturated starts can stall
        )
        return Fit(effects, params)

    def warm(self, start: Fit | None, effects: frozenset[str]) -> dict[str, float] | None:
        return None if start is None else start.params


def _flat(image: torch.Tensor, pixels: torch.Tensor | None) -> torch.Tensor:
    flat = image.reshape(3, -1)
    return (flat if pixels is None else flat[:, pixels]).T


# ---------------------------------------------------------------------------------------------------------------
# light projection


class ProjectionFrames(PixelProblem):
    attack = "light_projection"
    base_model = "alpha blend of the scene and the projected image (the paper's light projection)"
    extended_model = "additive projector light"
    candidates = PROJECTION_EFFECTS

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        if any(p.pattern is None for p in pairs):
            raise ValueError(
                "light_projection frame pairs need a 'pattern' column: the image the attacker projected"
            )
        super().__init__(pairs, seed)

    def features(self, index: int, pixels: torch.Tensor | None) -> dict[str, torch.Tensor]:
        pair = self.pairs[index]
        surface = _flat(pair.clean, pixels)
        return {
            "surface": surface,
            "projected": _flat(pair.pattern, pixels),
            "strength": torch.full((len(surface), 1), pair.intensity, dtype=torch.float64),
        }

    def predict_features(self, effects, params, feats):
        return projection_predict(feats["surface"], feats["projected"], feats["strength"], effects, params)

    def param_specs(self, effects):
        return projection_specs(effects)

    def warm(self, start: Fit | None, effects: frozenset[str]) -> dict[str, float] | None:
        return projection_warm(start, effects)

    def transform_kwargs(self, fit: Fit) -> dict:
        return projection_kwargs(fit)


# ---------------------------------------------------------------------------------------------------------------
# laser blinding

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
            [_flat(p.pattern, torch.as_tensor(probe_rng.choice(p.height * p.width, 1024))) for p in pairs]
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
            "scene": _flat(pair.clean, pixels),
            "pattern": _flat(pair.pattern, pixels),
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


# ---------------------------------------------------------------------------------------------------------------
# ultrasound blur

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


# ---------------------------------------------------------------------------------------------------------------
# EM color strip

EM_EFFECTS = (
    Effect(
        "bayer_phase_flip",
        "interference drops an odd number of rows from the video stream; every later row is then demosaiced with "
        "the colour-filter phase off by one, so the wrong colours run from that row to the frame's end instead "
        "of alternating in periodic bands",
    ),
)


class EMStripFrames(FrameProblem):
    """Rows are either decoded correctly or through the wrong colour map; where they go wrong is per frame."""

    attack = "em_color_strip"
    base_model = (
        "periodic bands of mis-decoded colour (the paper's EM color strip; period, phase, colour fitted)"
    )
    extended_model = "Bayer phase flip"
    candidates = EM_EFFECTS
    periods = tuple(np.linspace(0.04, 1.0, 49))  # band period as a share of the frame height

    def row_costs(self, params, index: int) -> tuple[np.ndarray, np.ndarray]:
        pair = self.pairs[index]
        mapped = physics.em_color_map(pair.clean.unsqueeze(0), params["gain"], params["offset"])[0]
        keep = ((pair.attacked - pair.clean) ** 2).sum(dim=(0, 2)).numpy()
        swap = ((pair.attacked - mapped) ** 2).sum(dim=(0, 2)).numpy()
        return keep, swap

    @staticmethod
    def best_band_phase(keep, swap, period_rows: float) -> tuple[float, float]:
        rows = np.arange(len(keep))
        best = (np.inf, 0.0)
        for phase in np.linspace(0, period_rows, max(2, int(period_rows) + 1), endpoint=False):
            mask = np.remainder(rows - phase, period_rows) < 0.5 * period_rows
            cost = float(np.where(mask, swap, keep).sum())
            best = min(best, (cost, float(phase)))
        return best

    @staticmethod
    def best_flip_row(keep, swap) -> tuple[float, int]:
        # cost(start) = sum(keep[:start]) + sum(swap[start:])
        costs = np.concatenate([[0.0], np.cumsum(keep)]) + np.concatenate(
            [np.cumsum(swap[::-1])[::-1], [0.0]]
        )
        start = int(np.argmin(costs))
        return float(costs[start]), start

    def placements(self, effects, params, items) -> dict[int, tuple[str, float]]:
        """Per-frame placement (band phase or flip row): estimated from each frame itself, also when held out."""
        out = {}
        for i in items:
            keep, swap = self.row_costs(params, int(i))
            if "bayer_phase_flip" in effects:
                out[int(i)] = ("flip", float(self.best_flip_row(keep, swap)[1]))
            else:
                period = params["period"] * self.pairs[int(i)].height
                out[int(i)] = ("bands", self.best_band_phase(keep, swap, period)[1])
        return out

    def mask(self, effects, params, index: int, placement) -> torch.Tensor:
        height = self.pairs[index].height
        kind, value = placement
        if kind == "flip":
            return physics.bayer_flip_mask(height, value)[0].double()
        return physics.periodic_band_mask(height, params["period"] * height, value)[0].double()

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        placement = self.placements(fit.effects, fit.params, [index])[index]
        pair = self.pairs[index]
        mask = self.mask(fit.effects, fit.params, index, placement)
        mapped = physics.em_color_map(pair.clean.unsqueeze(0), fit.params["gain"], fit.params["offset"])[0]
        return mask * mapped + (1 - mask) * pair.clean

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        params = {"gain": 2.5, "offset": 50.0 / 255.0, "period": 0.25}
        for _ in range(3):  # alternate: placement given the colour map, colour map given the placement
            if "bayer_phase_flip" not in effects:
                costs = {}
                for period in self.periods:
                    total = 0.0
                    for i in items:
                        keep, swap = self.row_costs(params, int(i))
                        total += self.best_band_phase(keep, swap, period * self.pairs[int(i)].height)[0]
                    costs[period] = total
                params["period"] = float(min(costs, key=costs.__getitem__))
            placement = self.placements(effects, params, items)
            masks = {
                int(i): self.mask(effects, params, int(i), placement[int(i)])[0, :, 0].bool() for i in items
            }

            def residuals(p, masks=masks):
                parts = []
                for i in items:
                    pair = self.pairs[int(i)]
                    rows = masks[int(i)]
                    if rows.any():
                        mapped = physics.em_color_map(
                            pair.clean[:, rows].unsqueeze(0), p["gain"], p["offset"]
                        )[0]
                        parts.append((mapped - pair.attacked[:, rows]).ravel())
                return torch.cat(parts) if parts else torch.zeros(1, dtype=torch.float64)

            colour = fit_least_squares(
                [Param("gain", params["gain"], 0.0, 10.0), Param("offset", params["offset"], -1.0, 1.0, 0.1)],
                residuals,
            )
            params.update(colour)
        if "bayer_phase_flip" in effects:
            params.pop("period")
        return Fit(effects, params)

    def transform_kwargs(self, fit: Fit) -> dict:
        """``EMColorStrip`` options: the Bayer-flip model with the fitted colour map (the paper's bands: none)."""
        if "bayer_phase_flip" in fit.effects:
            return {"model": "bayer_phase_flip", "gain": fit.params["gain"], "offset": fit.params["offset"]}
        return {}


FRAME_PROBLEMS = {
    "laser_blinding": BlindingFrames,
    "light_projection": ProjectionFrames,
    "ultrasound_blur": BlurFrames,
    "em_color_strip": EMStripFrames,
}
