"""Laser captures without a scene -> ``laser_blinding``'s pattern.

Base: the best-fitting Gaussian spot (what a simple simulation would draw). Extensions: the spot's light is linear
irradiance that saturates the sensor before the tone curve (a flat white core of a measurable radius) and glare
that falls off as a power law. Items are square tiles of the capture; held-out tiles are never fitted.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.core import (
    Effect,
    Fit,
    Param,
    Problem,
    binned_rmse,
    fit_least_squares,
    further_starts,
)
from lerobot_phantom.calibration.frame_models.common import REFERENCE_SIZE, SENSOR_GAMMA, load_rgb
from lerobot_phantom.calibration.structure import ResidualSample
from lerobot_phantom.calibration.tone import GAMMA_PARAM
from lerobot_phantom.transforms import physics

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")

CAPTURE_EFFECTS = (
    Effect(
        "linear_light_saturation",
        "the laser's light is linear irradiance that clips at the sensor's full well before the gamma curve: the "
        "spot has a flat saturated (white) core and a coloured rim, which a Gaussian in pixel values cannot draw",
    ),
    Effect(
        "halo_power_law",
        "light scattered in the lens and on the sensor makes a glare that falls off as a power of the distance "
        "(r^-k), far wider than the Gaussian's exponential tail",
    ),
    Effect(
        SENSOR_GAMMA.name,
        "the camera's tone curve is not the sRGB standard: a fitted power law maps irradiance to pixel values",
        requires=("linear_light_saturation",),
    ),
)


def capture_files(path: Path) -> list[Path]:
    if path.is_file():
        return [path]
    files = sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
    if not files:
        raise ValueError(f"{path} holds no laser captures ({', '.join(IMAGE_SUFFIXES)})")
    return files


class CaptureProblem(Problem):
    """One capture of a laser shining into the camera."""

    attack = "laser_blinding"
    input_kind = "laser_captures"
    units = "grey levels (0-255)"
    base_model = "best-fitting Gaussian spot"
    extended_model = "saturating laser spot with glare"
    candidates = CAPTURE_EFFECTS
    tile = 8
    max_fit_pixels = 3000

    def __init__(self, path: Path, *, max_side: int, seed: int) -> None:
        from PIL import Image

        with Image.open(path) as probe:
            self.original_size = probe.size
        self.path = path
        self.image = load_rgb(path, max_side=max_side)
        _, height, width = self.image.shape
        self.scale_to_original = max(self.original_size) / max(height, width)
        self.to_reference = REFERENCE_SIZE / max(height, width)
        ys, xs = torch.meshgrid(
            torch.arange(height, dtype=torch.float64), torch.arange(width, dtype=torch.float64), indexing="ij"
        )
        self.xs, self.ys = xs.reshape(-1), ys.reshape(-1)
        tiles_x = -(-width // self.tile)
        self.tile_of_pixel = ((ys // self.tile) * tiles_x + (xs // self.tile)).long().reshape(-1).numpy()
        self.n_tiles = int(self.tile_of_pixel.max()) + 1
        self.values = self.image.reshape(3, -1).T
        order = np.argsort(self.tile_of_pixel, kind="stable")
        bounds = np.searchsorted(self.tile_of_pixel[order], np.arange(self.n_tiles + 1))
        self.tile_pixels = [order[bounds[t] : bounds[t + 1]] for t in range(self.n_tiles)]
        self.seed = seed

    @property
    def n_items(self) -> int:
        return self.n_tiles

    def pixels(self, items: np.ndarray, cap: int | None = None) -> torch.Tensor:
        """Pixel indices of the tiles ``items`` (a repeated tile repeats its pixels, as a bootstrap draw needs);
        at most ``cap`` of them, a sample seeded by ``--seed`` and the tiles drawn."""
        chosen = np.concatenate([self.tile_pixels[int(t)] for t in items]) if len(items) else np.zeros(0, int)
        if cap is not None and len(chosen) > cap:
            rng = np.random.default_rng([self.seed, len(chosen), int(np.sum(items))])
            chosen = np.sort(rng.choice(chosen, cap, replace=False))
        return torch.as_tensor(chosen)

    def initial_guess(self, items: np.ndarray) -> dict[str, float]:
        """Start values read from the fit tiles ``items`` only (held-out tiles never inform a fit)."""
        pixels = self.pixels(np.unique(items))
        values, xs, ys = self.values[pixels], self.xs[pixels], self.ys[pixels]
        # areas measured on the fit tiles stand for the whole capture's
        area_scale = self.n_tiles / max(len(np.unique(items)), 1)
        luminance = values.mean(1)
        background = values.median(0).values
        peak = float(luminance.max())
        bright = luminance >= peak - 0.05 * max(peak - float(luminance.min()), 1e-6)
        half = luminance >= 0.5 * (peak + float(luminance.median()))
        sigma = max(1.0, float(np.sqrt(area_scale * half.sum().item() / np.pi)) / 1.18)
        guess = {"cx": float(xs[bright].mean()), "cy": float(ys[bright].mean()), "sigma": sigma}
        # a saturating spot: channel c clips inside radius R_c where A_c * exp(-R_c^2 / 2 sigma^2) = 1; take the
        # weakest saturated channel's disc as ~1.5 sigma
        saturated = [area_scale * float((values[:, c] >= 0.98).sum()) for c in range(3)]
        radii = [float(np.sqrt(n / np.pi)) for n in saturated]
        core = min([r for r in radii if r > 0] or [sigma])
        guess["linear_sigma"] = max(core / 1.5, 1.0)
        for c, name in enumerate("rgb"):
            guess[f"background_{name}"] = float(background[c])
            guess[f"amplitude_{name}"] = max(float(values[:, c].max() - background[c]), 1e-3)
            log_amplitude = (
                radii[c] ** 2 / (2 * guess["linear_sigma"] ** 2) / np.log(10) if radii[c] > 0 else -1.0
            )
            guess[f"log10_amplitude_{name}"] = float(np.clip(log_amplitude, -3.0, 6.0))
        return guess

    def param_specs(self, effects: frozenset[str], guess: dict[str, float] | None = None) -> list[Param]:
        g = guess if guess is not None else self.initial_guess(np.arange(self.n_tiles))
        _, height, width = self.image.shape
        size = float(max(height, width))
        linear = "linear_light_saturation" in effects
        sigma = g["linear_sigma"] if linear else g["sigma"]
        specs = [
            Param("cx", g["cx"], -0.5 * width, 1.5 * width, scale=size / 10),
            Param("cy", g["cy"], -0.5 * height, 1.5 * height, scale=size / 10),
            Param("sigma", sigma, 0.3, 2.0 * size, scale=sigma),
        ]
        for name in "rgb":
            specs.append(Param(f"background_{name}", g[f"background_{name}"], 0.0, 1.0, scale=0.1))
            if linear:  # irradiance spans decades: fit its logarithm
                specs.append(Param(f"log10_amplitude_{name}", g[f"log10_amplitude_{name}"], -3.0, 6.0))
            else:
                specs.append(Param(f"amplitude_{name}", g[f"amplitude_{name}"], 0.0, 2.0, scale=0.3))
        if "halo_power_law" in effects:
            # relative to the core's peak; start where the glare next to the core is about the white level
            strongest = max(g[f"log10_amplitude_{c}"] for c in "rgb") if linear else 0.0
            specs += [
                Param("log10_halo_amplitude", -max(strongest, 1.0), -9.0, 1.0),
                Param("halo_exponent", 2.0, 0.2, 8.0, scale=1.0),
                Param("halo_scale", sigma, 0.1, 4.0 * size, scale=sigma),
            ]
        if "sensor_gamma" in effects:
            specs.append(GAMMA_PARAM)
        return specs

    def predict(self, effects, p, pixels: torch.Tensor) -> torch.Tensor:
        # not torch.hypot: its derivative is 0/0 on a pixel at the spot's centre, and forward-mode autodiff spreads
        # that NaN to every column of the Jacobian; 1e-12 px^2 changes no radius that matters
        radius = torch.sqrt((self.xs[pixels] - p["cx"]) ** 2 + (self.ys[pixels] - p["cy"]) ** 2 + 1e-12)
        profile = physics.laser_spot_profile(
            radius,
            p["sigma"],
            halo_amplitude=10.0 ** p["log10_halo_amplitude"] if "halo_power_law" in effects else 0.0,
            halo_exponent=p.get("halo_exponent", 2.0),
            halo_scale=p.get("halo_scale", 1.0),
        ).unsqueeze(1)
        background = torch.stack([torch.as_tensor(p[f"background_{c}"], dtype=torch.float64) for c in "rgb"])
        if "linear_light_saturation" not in effects:
            amplitude = torch.stack(
                [torch.as_tensor(p[f"amplitude_{c}"], dtype=torch.float64) for c in "rgb"]
            )
            return (background + amplitude * profile).clamp(0.0, 1.0)
        gamma = p["gamma"] if "sensor_gamma" in effects else None
        amplitude = 10.0 ** torch.stack(
            [torch.as_tensor(p[f"log10_amplitude_{c}"], dtype=torch.float64) for c in "rgb"]
        )
        irradiance = physics.decode(background, gamma) + amplitude * profile
        return physics.encode(irradiance.clamp(0.0, 1.0), gamma)

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        pixels = self.pixels(items, self.max_fit_pixels)
        target = self.values[pixels]
        warm = None
        if start is not None:
            warm = dict(start.params)
            if "linear_light_saturation" in effects and "linear_light_saturation" not in start.effects:
                # a saturating spot's core is narrower than the Gaussian that best fits it, and its glare is
                # relative to a far higher peak
                warm.pop("sigma")
                warm.pop("log10_halo_amplitude", None)
        refit = start is not None and start.effects == effects  # a bootstrap draw: start from the estimate
        params = fit_least_squares(
            self.param_specs(effects, self.initial_guess(items)),
            lambda p: (self.predict(effects, p, pixels) - target).ravel(),
            warm=warm,
            starts=further_starts(start, effects),
            max_nfev=20 if refit else 60,
        )
        return Fit(effects, params)

    def residual(self, fit: Fit, items: np.ndarray) -> tuple[torch.Tensor, np.ndarray]:
        pixels = self.pixels(items)
        with torch.no_grad():
            return 255.0 * (
                self.predict(fit.effects, fit.params, pixels) - self.values[pixels]
            ), pixels.numpy()

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        r, _ = self.residual(fit, items)
        return float((r**2).sum()), r.numel()

    def item_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        unique, inverse = np.unique(items, return_inverse=True)
        r, pixels = self.residual(fit, unique)
        tiles = np.searchsorted(unique, self.tile_of_pixel[pixels])
        sq = np.bincount(tiles, weights=(r**2).sum(1).numpy(), minlength=len(unique))
        counts = 3.0 * np.bincount(tiles, minlength=len(unique))
        return sq[inverse], counts[inverse]

    def analyse(self, fit: Fit, items: np.ndarray) -> dict:
        r, pixels = self.residual(fit, items)
        radius = np.hypot(
            self.xs.numpy()[pixels] - fit.params["cx"], self.ys.numpy()[pixels] - fit.params["cy"]
        )
        r = r.numpy()
        return {
            "radius_px": binned_rmse(np.repeat(radius[:, None] * self.scale_to_original, 3, 1), r, bins=10),
            "channel": binned_rmse(np.broadcast_to(np.arange(3), r.shape), r),
            "measured_level": binned_rmse(self.values.numpy()[pixels] * 255, r),
        }

    def residual_sample(self, fit: Fit, items: np.ndarray, rng: np.random.Generator) -> ResidualSample:
        """Per tile: residuals against the distance from the fitted spot centre, the measured level, channel."""
        sample = ResidualSample([], {"radius_px": [], "measured_level": [], "channel": []})
        r, pixels = self.residual(fit, np.unique(items))
        r = r.numpy()
        tiles = self.tile_of_pixel[pixels]
        radius = np.hypot(
            self.xs.numpy()[pixels] - fit.params["cx"], self.ys.numpy()[pixels] - fit.params["cy"]
        )
        level = self.values.numpy()[pixels] * 255
        for tile in np.unique(tiles):
            mine = tiles == tile
            sample.residual.append(r[mine].ravel())
            sample.covariates["radius_px"].append(np.repeat(radius[mine] * self.scale_to_original, 3))
            sample.covariates["measured_level"].append(level[mine].ravel())
            sample.covariates["channel"].append(np.tile(np.arange(3.0), int(mine.sum())))
        return sample

    def evidence(self, effect: str, before: Fit, after: Fit, items: np.ndarray) -> str:
        analysis = self.analyse(before, items)["radius_px"]
        worst = int(np.argmax(analysis["rmse"]))
        return (
            f"before {effect} the residual is largest at radius ~{analysis['x'][worst]:.0f} px "
            f"({analysis['rmse'][worst]:.1f} grey levels)"
        )

    def derived(self, fit: Fit) -> dict:
        p = fit.params
        linear = "linear_light_saturation" in fit.effects
        amplitudes = {c: 10.0 ** p[f"log10_amplitude_{c}"] if linear else p[f"amplitude_{c}"] for c in "rgb"}
        peak_channel = max("rgb", key=amplitudes.__getitem__)
        gamma = p.get("gamma") if "sensor_gamma" in fit.effects else None
        background = (
            float(physics.decode(torch.tensor(p[f"background_{peak_channel}"]), gamma))
            if linear
            else (p[f"background_{peak_channel}"])
        )
        halo = "halo_power_law" in fit.effects
        radius = physics.saturation_radius(
            amplitudes[peak_channel],
            p["sigma"],
            halo_amplitude=10.0 ** p["log10_halo_amplitude"] if halo else 0.0,
            halo_exponent=p.get("halo_exponent", 2.0),
            halo_scale=p.get("halo_scale", 1.0),
            white=max(1.0 - background, 1e-6),
        )
        out = {
            "capture": self.path.name,
            "centre_px": [p["cx"] * self.scale_to_original, p["cy"] * self.scale_to_original],
            "core_sigma_px": p["sigma"] * self.scale_to_original,
            "saturation_radius_px": radius * self.scale_to_original,
            "saturation_radius_ref_px": radius * self.to_reference,
            "peak_over_white": amplitudes[peak_channel] / max(1.0 - background, 1e-6),
        }
        if halo:
            out["halo_exponent"] = p["halo_exponent"]
            out["halo_scale_px"] = p["halo_scale"] * self.scale_to_original
        return out

    def render(self, fit: Fit) -> torch.Tensor:
        _, height, width = self.image.shape
        with torch.no_grad():
            flat = self.predict(fit.effects, fit.params, torch.arange(height * width))
        return flat.T.reshape(3, height, width)


class MultiCapture(Problem):
    """Several captures fitted with one shared set of effects (each capture keeps its own parameters)."""

    attack = CaptureProblem.attack
    input_kind = CaptureProblem.input_kind
    units = CaptureProblem.units
    base_model = CaptureProblem.base_model
    extended_model = CaptureProblem.extended_model
    candidates = CAPTURE_EFFECTS

    def __init__(self, path: Path, *, max_side: int, seed: int) -> None:
        self.item_name = f"{CaptureProblem.tile}x{CaptureProblem.tile}-pixel tiles (captures resized to at most {max_side} px)"
        self.captures = [CaptureProblem(f, max_side=max_side, seed=seed) for f in capture_files(path)]
        self.offsets = np.cumsum([0] + [c.n_items for c in self.captures])

    @property
    def n_items(self) -> int:
        return int(self.offsets[-1])

    def local(self, items: np.ndarray):
        for k, capture in enumerate(self.captures):
            chosen = items[(items >= self.offsets[k]) & (items < self.offsets[k + 1])] - self.offsets[k]
            yield k, capture, chosen

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        fits = [
            capture.fit(effects, chosen, None if start is None else start.extra["fits"][k])
            for k, capture, chosen in self.local(items)
        ]
        params = {
            f"{c.path.name}.{k}": v
            for c, f in zip(self.captures, fits, strict=True)
            for k, v in f.params.items()
        }
        return Fit(effects, params, {"fits": fits})

    def capture_fits(self, fit: Fit) -> list[Fit]:
        """Each capture's fit, its parameters read from ``fit.params``, where they are reported (and moved:
        ``identify.unmeasured_params``)."""
        return [
            Fit(f.effects, {k: fit.params[f"{c.path.name}.{k}"] for k in f.params}, f.extra)
            for c, f in zip(self.captures, fit.extra["fits"], strict=True)
        ]

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        total, count = 0.0, 0
        fits = self.capture_fits(fit)
        for k, capture, chosen in self.local(items):
            if len(chosen):
                sq, n = capture.squared_errors(fits[k], chosen)
                total, count = total + sq, count + n
        return total, count

    def item_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        sq, counts = np.zeros(len(items)), np.zeros(len(items))
        items = np.asarray(items)
        fits = self.capture_fits(fit)
        for k, capture in enumerate(self.captures):
            mine = np.flatnonzero((items >= self.offsets[k]) & (items < self.offsets[k + 1]))
            if len(mine):
                sq[mine], counts[mine] = capture.item_squared_errors(fits[k], items[mine] - self.offsets[k])
        return sq, counts

    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        return [
            dataclasses.replace(p, name=f"{c.path.name}.{p.name}")
            for c in self.captures
            for p in c.param_specs(effects)
        ]

    def per_capture_rmse(self, fit: Fit, items: np.ndarray) -> dict[str, float]:
        fits = self.capture_fits(fit)
        return {
            capture.path.name: capture.rmse(fits[k], chosen)
            for k, capture, chosen in self.local(items)
            if len(chosen)
        }

    def analyse(self, fit: Fit, items: np.ndarray) -> dict:
        fits = self.capture_fits(fit)
        return {
            f"{capture.path.name}:{name}": values
            for k, capture, chosen in self.local(items)
            for name, values in capture.analyse(fits[k], chosen).items()
            if name == "radius_px"
        }

    def evidence(self, effect: str, before: Fit, after: Fit, items: np.ndarray) -> str:
        befores, afters = self.capture_fits(before), self.capture_fits(after)
        return "; ".join(
            f"{capture.path.name}: {capture.evidence(effect, befores[k], afters[k], chosen)}"
            for k, capture, chosen in self.local(items)
        )

    def residual_sample(self, fit: Fit, items: np.ndarray, rng: np.random.Generator) -> ResidualSample:
        sample = ResidualSample([], {"radius_px": [], "measured_level": [], "channel": []})
        fits = self.capture_fits(fit)
        for k, capture, chosen in self.local(items):
            if len(chosen):
                part = capture.residual_sample(fits[k], chosen, rng)
                sample.residual += part.residual
                for name in sample.covariates:
                    sample.covariates[name] += part.covariates[name]
        return sample

    def derived(self, fit: Fit) -> dict:
        per_capture = [c.derived(f) for c, f in zip(self.captures, self.capture_fits(fit), strict=True)]
        out: dict = {"captures": per_capture}
        for key in ("halo_exponent", "saturation_radius_px", "saturation_radius_ref_px", "core_sigma_px"):
            values = [d[key] for d in per_capture if key in d]
            if values:
                out[f"median_{key}"] = float(np.median(values))
        return out

    def transform_kwargs(self, fit: Fit) -> dict:
        """``LaserBlinding`` options shaping its procedural spot like the captures (the recorded pattern's own
        glare), and the physical injection when the captures saturate."""
        d = self.derived(fit)
        kwargs: dict = {}
        if "linear_light_saturation" in fit.effects:
            kwargs["model"] = "physical"
        if "halo_power_law" in fit.effects:
            kwargs["halo_exponent"] = d["median_halo_exponent"]
        radius = float(np.median([c["saturation_radius_ref_px"] for c in d["captures"]])) / 256.0
        if radius > 0:  # the procedural spot's saturated core, as a share of the 256-pixel reference side
            kwargs["core_radius"] = radius
        return kwargs

    def figures(self, base: Fit, extended: Fit, items: np.ndarray, out_dir: Path) -> list[str]:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        names = []
        bases, extendeds = self.capture_fits(base), self.capture_fits(extended)
        for k, capture in enumerate(self.captures):
            fig, axes = plt.subplots(1, 4, figsize=(15, 4))
            measured = capture.image
            base_img = capture.render(bases[k])
            ext_img = capture.render(extendeds[k])
            for ax, image, title in zip(
                axes[:3],
                (measured, base_img, ext_img),
                ("measured", "Gaussian spot (base)", "extended"),
                strict=True,
            ):
                ax.imshow(image.permute(1, 2, 0).numpy())
                ax.set_title(title)
                ax.axis("off")
            p = extendeds[k].params
            cy = int(np.clip(round(p["cy"]), 0, measured.shape[1] - 1))
            for image, label in ((measured, "measured"), (base_img, "base"), (ext_img, "extended")):
                axes[3].plot(255 * image.max(0).values[cy].numpy(), label=label)
            axes[3].set(title="row through the spot (max channel)", xlabel="x (px)", ylabel="grey level")
            axes[3].legend()
            fig.tight_layout()
            path = out_dir / f"capture_{k}_{capture.path.stem}.png"
            fig.savefig(path, dpi=80)
            plt.close(fig)
            names.append(path.name)
        return names
