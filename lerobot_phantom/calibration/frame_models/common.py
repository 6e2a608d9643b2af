"""Frame pairs -> any camera attack: the shared part (loading ``pairs.csv``, per-pair scoring, residuals).

A folder holds ``pairs.csv`` (clean, attacked[, pattern[, pattern_dark]][, intensity], ...): ``pattern_dark`` is
the pattern's capture repeated with the source off (a dark frame), for the models that read one. Items are whole
image pairs (held-out pairs are never seen while fitting). Frames are resized so that their longer side is at most
``max_side`` pixels (area averaging); pixel-sized parameters are reported on the package's 256-pixel reference
scale. Each attack's frame model lives in its own module of this package.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import torch
from PIL import Image
from scipy.special import logsumexp

from lerobot_phantom.calibration.core import (
    Effect,
    Fit,
    Param,
    Problem,
    binned_rmse,
    fit_least_squares,
    further_starts,
)
from lerobot_phantom.calibration.noise import NoiseSample, NoiseSources, noise_sample, tone_curve, unclipped
from lerobot_phantom.calibration.structure import LAG, NeighbourPairs, ResidualSample, line_terms
from lerobot_phantom.transforms.base import REFERENCE_SIZE
from lerobot_phantom.transforms.physics import gaussian_spread


class ParameterMemo:
    """Values of a pure function of a few fit parameters, kept for the last ``size`` keys.

    A finite-difference Jacobian moves one parameter at a time, so every column that moves another parameter
    repeats the value at the point it is taken at: a frame decoded under the fitted tone curve, light spread over
    the frame. ``key()`` gives what the value depends on (the parameters' values as floats); ``anchor`` is the
    tensor the value was computed from, kept with it, so that its id in a key cannot be reused by another tensor
    while the entry lives. Never under autograd: a Jacobian taken by torch differentiates through the value, which
    a kept one would cut, and its parameters have no float values to key on."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.entries: OrderedDict = OrderedDict()

    def __len__(self) -> int:
        return len(self.entries)

    def clear(self) -> None:
        self.entries.clear()

    def get(
        self, anchor: torch.Tensor, key: Callable[[], tuple], compute: Callable[[], torch.Tensor]
    ) -> torch.Tensor:
        if torch.is_grad_enabled():
            return compute()
        key = (id(anchor), *key())
        kept = self.entries.get(key)
        if kept is not None and kept[0] is anchor:
            self.entries.move_to_end(key)
            return kept[1]
        value = compute()
        self.entries[key] = (anchor, value)
        if len(self.entries) > self.size:
            self.entries.popitem(last=False)
        return value


def parameter_values(params: dict, names) -> tuple[tuple[str, float], ...]:
    """(name, value) of those of ``names`` that ``params`` holds, in ``names``' order: a memo key (with the names,
    since which of them a model has can change the value as much as what they are)."""
    return tuple((n, float(params[n])) for n in names if n in params)


SENSOR_GAMMA = Effect(
    "sensor_gamma",
    "the camera composes light in linear irradiance but stores gamma-encoded values, so effects that add or "
    "average light are wrong when applied to the encoded pixel values",
)


SIXTEEN_BIT_GREY_MODES = ("I;16", "I;16B", "I;16L", "I;16N")
"""Pillow's modes of a 16-bit grey image (a machine-vision camera's PNG or TIFF); a PNG's 32-bit "I" holds one too
(PNG stores at most 16 bits). ``Image.convert("RGB")`` clips these at 255 of 65535, which would read a dark capture
as white, so they are scaled by their own range."""


def sixteen_bit_colour(opened: Image.Image) -> bool:
    """Whether Pillow opened a 16-bit-per-channel colour file (a 48-bit RGB or 64-bit RGBA PNG or TIFF): it reads
    these as 8-bit RGB(A), the right scale with the low byte of every value dropped."""
    if opened.mode not in ("RGB", "RGBA") or not opened.tile:
        return False
    args = opened.tile[0].args
    rawmode = args if isinstance(args, str) else args[0] if args else ""
    return isinstance(rawmode, str) and ";16" in rawmode


def sixteen_bit_channels(path: Path, opened: Image.Image) -> list[np.ndarray] | None:
    """The file's channels in [0, 1] (float32, one grey or red, green, blue) where it stores 16 bits a value, else
    None. Colour is decoded by OpenCV, which keeps all 16 bits."""
    if opened.mode in SIXTEEN_BIT_GREY_MODES or (opened.mode == "I" and opened.format == "PNG"):
        return [np.asarray(opened, dtype=np.float32) / 65535.0]
    if not sixteen_bit_colour(opened):
        return None
    decoded = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if decoded is None or decoded.dtype != np.uint16 or decoded.ndim != 3:
        raise ValueError(f"{path}: Pillow reads 16-bit colour that OpenCV does not decode as such")
    return [decoded[..., channel].astype(np.float32) / 65535.0 for channel in (2, 1, 0)]  # OpenCV's BGR(A)


def load_rgb(path: Path, size: tuple[int, int] | None = None, max_side: int | None = None) -> torch.Tensor:
    """An image file -> float64 (3, H, W) in [0, 1] (alpha dropped; grey repeated in each channel; 16-bit values,
    grey or colour, scaled by 65535), resized to ``size`` (W, H) or ``max_side`` (area averaging)."""
    if not path.is_file():
        raise FileNotFoundError(f"image not found: {path}")
    with Image.open(path) as opened:
        channels = sixteen_bit_channels(path, opened)
        if channels is not None:
            images = [Image.fromarray(channel) for channel in channels]
        elif opened.mode in ("I", "F"):
            raise ValueError(
                f"{path}: a {opened.format} image of Pillow mode {opened.mode!r} (32-bit values) has no stated "
                "range of grey levels; store the capture as 8-bit or 16-bit PNG or TIFF (readable modes: any "
                f"8-bit mode, {', '.join(SIXTEEN_BIT_GREY_MODES)}, 16-bit RGB)"
            )
        else:
            images = [opened.convert("RGB")]
    width, height = images[0].size
    if size is None and max_side is not None and max(width, height) > max_side:
        factor = max_side / max(width, height)
        size = (max(1, round(width * factor)), max(1, round(height * factor)))
    if size is not None and (width, height) != tuple(size):
        images = [image.resize(tuple(size), Image.Resampling.BOX) for image in images]
    if images[0].mode == "RGB":
        return torch.from_numpy(np.asarray(images[0], dtype=np.float64) / 255.0).permute(2, 0, 1).contiguous()
    planes = torch.stack([torch.from_numpy(np.asarray(image, dtype=np.float64)) for image in images])
    return planes.expand(3, *planes.shape[1:]).clone()


@dataclass
class Pair:
    name: str
    clean: torch.Tensor
    attacked: torch.Tensor
    pattern: torch.Tensor | None
    intensity: float
    settings: dict = field(default_factory=dict)
    original_size: tuple[int, int] = (0, 0)  # (W, H) before resizing
    pattern_dark: torch.Tensor | None = None  # the pattern's capture with the source off

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


IMAGE_COLUMNS = ("clean", "attacked", "pattern", "pattern_dark")


def optional_image(folder: Path, row: pd.Series, column: str, size) -> torch.Tensor | None:
    """The image a row names in an optional column (None where the column is absent or the cell empty)."""
    name = row.get(column)
    return load_rgb(folder / name, size=size) if isinstance(name, str) and name else None


def load_pairs(folder: Path, *, max_side: int) -> list[Pair]:
    table_path = folder / "pairs.csv"
    if not table_path.is_file():
        raise FileNotFoundError(
            f"{folder} has no pairs.csv (columns clean,attacked[,pattern[,pattern_dark]][,intensity],...)"
        )
    table = pd.read_csv(table_path)
    for column in ("clean", "attacked"):
        if column not in table.columns:
            raise ValueError(
                f"{table_path} lacks column {column!r}; needs clean,attacked[,pattern[,pattern_dark]][,intensity]"
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
        pattern = optional_image(folder, row, "pattern", size)
        pattern_dark = optional_image(folder, row, "pattern_dark", size)
        if pattern_dark is not None and pattern is None:
            raise ValueError(
                f"pair {i}: pattern_dark {row['pattern_dark']} is the pattern's capture with the source off, but "
                "the pair has no pattern"
            )
        intensity = 1.0
        if "intensity" in table.columns and not pd.isna(row["intensity"]):
            intensity = float(row["intensity"])
            if not 0.0 <= intensity <= 1.0:
                raise ValueError(f"pair {i}: intensity must lie in [0, 1], got {intensity}")
        extra = {k: row[k] for k in table.columns if k not in (*IMAGE_COLUMNS, "intensity")}
        pairs.append(
            Pair(str(row["attacked"]), clean, attacked, pattern, intensity, extra, original, pattern_dark)
        )
    if len(pairs) < 2:
        raise ValueError(
            f"{table_path}: need at least 2 pairs (one to fit, one to hold out), got {len(pairs)}"
        )
    return pairs


class FrameProblem(Problem):
    """Shared machinery: per-pair prediction, squared errors, residual analysis and figures."""

    input_kind = "frame_pairs"
    units = "grey levels (0-255)"
    item_name = "whole image pairs"
    structure_values_per_pair = 4000
    # whether the model reads a pattern's dark frame (pairs.csv's pattern_dark); one it would ignore is refused
    reads_pattern_dark = False

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        if not self.reads_pattern_dark and any(p.pattern_dark is not None for p in pairs):
            raise ValueError(
                f"{self.attack}'s frame model reads no pattern_dark (a dark frame of the pattern's capture; "
                "laser_blinding reads one): drop the column"
            )
        self.pairs = pairs
        self.seed = seed

    def residual_sample(self, fit: Fit, items: np.ndarray, rng: np.random.Generator) -> ResidualSample:
        """Held-out residuals (grey levels) on a seeded sample of values per pair, against row and column
        position, the clean pixel's level, the channel, the pair's intensity and, when the pairs record the attack's
        pattern, the pattern's local detail (:func:`pattern_detail`); neighbours ``LAG`` pixels apart along rows and
        columns of the channel-mean residual; and every row's and column's displacement terms
        (``structure.line_terms``, the whole frame)."""
        variables = ("row", "column", "clean_level", "channel", "intensity")
        with_pattern = all(p.pattern is not None for p in self.pairs)
        sample = ResidualSample(
            [], {k: [] for k in variables + (("pattern_detail",) if with_pattern else ())}
        )
        sample.neighbours = {
            "neighbours_along_rows": NeighbourPairs(),
            "neighbours_along_columns": NeighbourPairs(),
        }
        sample.lines = {"rows": [], "columns": []}
        for i in items:
            pair = self.pairs[int(i)]
            with torch.no_grad():
                prediction = self.predict_pair(fit, int(i))
            residual = (255.0 * (prediction - pair.attacked)).numpy()
            predicted, measured = 255.0 * prediction.numpy(), 255.0 * pair.attacked.numpy()
            _, height, width = residual.shape
            take = rng.choice(
                residual.size, min(self.structure_values_per_pair, residual.size), replace=False
            )
            c, y, x = np.unravel_index(take, residual.shape)
            sample.residual.append(residual[c, y, x])
            sample.covariates["row"].append(y / max(height - 1, 1))
            sample.covariates["column"].append(x / max(width - 1, 1))
            sample.covariates["clean_level"].append(255.0 * pair.clean.numpy()[c, y, x])
            sample.covariates["channel"].append(c.astype(np.float64))
            sample.covariates["intensity"].append(np.full(len(take), pair.intensity))
            if with_pattern:
                sample.covariates["pattern_detail"].append(pattern_detail(pair.pattern)[c, y, x])
            for direction, terms in line_terms(residual, predicted).items():
                sample.lines[direction].append(terms)
            noise_sample, noise_position = self.noise_terms(fit, int(i), predicted, measured, (c, y, x))
            sample.noise.append(noise_sample)
            for name, values in noise_position.items():
                sample.noise_position.setdefault(name, []).append(values)
            mean = residual.mean(0)
            for name, (a, b) in {
                "neighbours_along_rows": (mean[:, :-LAG], mean[:, LAG:]),
                "neighbours_along_columns": (mean[:-LAG], mean[LAG:]),
            }.items():
                pick = rng.choice(a.size, min(self.structure_values_per_pair, a.size), replace=False)
                sample.neighbours[name].pairs.append((a.ravel()[pick], b.ravel()[pick]))
        return sample

    def noise_terms(
        self,
        fit: Fit,
        index: int,
        predicted: np.ndarray,
        measured: np.ndarray,
        where: tuple[np.ndarray, np.ndarray, np.ndarray],
    ) -> tuple[NoiseSample, dict[str, np.ndarray]]:
        """The sensor-noise terms (``noise.NoiseSample``) of the sampled values ``where`` (channel, row, column) of
        pair ``index``'s predicted and measured frames (grey levels) that are not clipped, and their row and column
        (0-1)."""
        flat = np.ravel_multi_index(where, predicted.shape)
        flat = flat[unclipped(predicted.ravel()[flat], measured.ravel()[flat])]
        _, y, x = np.unravel_index(flat, predicted.shape)
        _, height, width = predicted.shape
        sample = noise_sample(predicted, measured, flat, tone_curve(fit), self.noise_sources(fit, index))
        return sample, {"row": y / max(height - 1, 1), "column": x / max(width - 1, 1)}

    def noise_sources(self, fit: Fit, index: int) -> NoiseSources:
        """Which sensor values pair ``index``'s predicted values carry the noise of (``noise.NoiseSources``): by
        default each its own, as where the attack adds or removes light before the sensor counts it or moves values
        unchanged after it (EM truncation's rows); a frame model whose values are mixed after the sensor says so."""
        return None

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


# how much farther from 1 the whole frame's gamma may lie than the mean of the gammas fitted on the pixels nearest the
# frame's centre and on the rest, each half with its own light: a tone curve acts on every pixel alike, so its gamma
# is the same in both halves and whole (camsim's planted power-law curves: 0.95-1.11 times), while a projector's
# falloff, its light weaker towards the frame's edges, bends the whole frame's pooled light where each half's is
# nearly straight (2.18-3.07 times on six master seeds; docs/bench/session59/gamma_by_position_6seeds.txt)
TONE_POSITION_EXCESS = 1.5


class PixelProblem(FrameProblem):
    """Attacks that act pixel by pixel given per-pixel features; fits use a seeded sample of pixels per pair."""

    pixels_per_pair = 800
    centre_name = "the frame's centre"  # what ``centre`` is, for the reports

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
        return self.fit_on_pixels(effects, items, [self.samples[int(i)] for i in items], start)

    def fit_on_pixels(
        self, effects: frozenset[str], items: np.ndarray, pixels: list[torch.Tensor], start: Fit | None = None
    ) -> Fit:
        """The model ``effects`` fitted on ``pixels`` of ``items`` (one index tensor per item, in ``items``'
        order); ``fit`` passes each item's seeded sample."""
        stacked, target = self.stacked_pixels(items, pixels)
        params = fit_least_squares(
            self.param_specs(effects),
            lambda p: (self.predict_features(effects, p, stacked) - target).ravel(),
            warm=self.warm(start, effects),
            starts=further_starts(start, effects),
        )
        return Fit(effects, params)

    def stacked_pixels(
        self, items: np.ndarray, pixels: list[torch.Tensor]
    ) -> tuple[dict[str, torch.Tensor], torch.Tensor]:
        """(features of ``pixels`` of ``items`` stacked in ``items``' order, the attacked values there (n, 3))."""
        feats = [self.features(int(i), rows) for i, rows in zip(items, pixels, strict=True)]
        stacked = {k: torch.cat([f[k] for f in feats]) for k in feats[0]}
        target = torch.cat(
            [
                self.pairs[int(i)].attacked.reshape(3, -1)[:, rows].T
                for i, rows in zip(items, pixels, strict=True)
            ]
        )
        return stacked, target

    def warm(self, start: Fit | None, effects: frozenset[str]) -> dict[str, float] | None:
        return None if start is None else start.params

    def gamma_by_position(self, fit: Fit, items: np.ndarray) -> list[float]:
        """The gamma of ``fit``'s model refitted on ``items``' sampled pixels nearest the frame's centre, and on the
        rest (``position_halves``), each half with all its own parameters."""
        return [
            self.fit_on_pixels(fit.effects, items, rows).params["gamma"]
            for rows in self.position_halves(items)
        ]

    def tone_position_checks(self, fit: Fit, items: np.ndarray) -> list[str]:
        """A camera's tone curve acts on every pixel alike: the written model refitted on the fit pairs' pixels
        nearest ``centre_name`` (``centre``), and on the rest, must find the gamma the whole frame does, within
        ``TONE_POSITION_EXCESS`` of the halves' mean departure from 1 and on the same side of it; the reasons it
        does not (none: it does)."""
        halves = self.gamma_by_position(fit, items)
        whole, halves_mean = fit.params["gamma"] - 1.0, float(np.mean(halves)) - 1.0
        fitted = (
            f"the gamma fitted on the pixels nearest {self.centre_name} ({halves[0]:.3f}) and on the rest "
            f"({halves[1]:.3f}), each half with its own light,"
        )
        if whole * halves_mean <= 0.0:
            return [f"{fitted} does not depart from 1 on the side the whole frame's ({1.0 + whole:.3f}) does"]
        if abs(whole) <= TONE_POSITION_EXCESS * abs(halves_mean):
            return []
        return [
            f"{fitted} departs from 1 by {abs(halves_mean):.3f} on average, the whole frame's ({1.0 + whole:.3f}) "
            f"{abs(whole / halves_mean):.2f} times as far, more than {TONE_POSITION_EXCESS:g}: a tone curve acts on "
            "every pixel alike, so the whole frame's bends light that changes across the frame"
        ]

    def position_halves(self, items: np.ndarray) -> tuple[list[torch.Tensor], list[torch.Tensor]]:
        """Each item's sampled pixels nearest its frame's centre and the rest, split at their median distance from
        it (in shares of the frame's sides, so both halves reach every side of a wide frame alike)."""
        inner, outer = [], []
        for i in items:
            pair, rows = self.pairs[int(i)], self.samples[int(i)]
            x_mid, y_mid = self.centre(int(i))
            y, x = rows // pair.width, rows % pair.width
            radius = torch.hypot((x - x_mid) / pair.width, (y - y_mid) / pair.height)
            near = radius <= radius.median()
            inner.append(rows[near])
            outer.append(rows[~near])
        return inner, outer


# the neighbourhood a pattern value is compared with: wider than demosaicing's and compression's one or two pixels,
# as narrow as the blur of a projector slightly out of focus or of a lens's point spread
DETAIL_SIGMA_PX = 1.5


def pattern_detail(pattern: torch.Tensor) -> np.ndarray:
    """The pattern (3, H, W) in grey levels minus its Gaussian-weighted neighbourhood mean, per channel: positive on
    the bright side of an edge, negative on the dark side, 0 where the pattern is flat. Light that spreads across the
    pattern's edges on its way to the sensor (optics blur, a projector's defocus), which no model term spreads,
    leaves a residual that follows this variable (camsim's optics blur of an emitted projector frame:
    docs/bench/session31.md)."""
    values = 255.0 * pattern.double()
    return (values - gaussian_spread(values[None], DETAIL_SIGMA_PX)[0]).numpy()


def flat_pixels(image: torch.Tensor, pixels: torch.Tensor | None) -> torch.Tensor:
    flat = image.reshape(3, -1)
    return (flat if pixels is None else flat[:, pixels]).T


class LatentFrameProblem(FrameProblem):
    """Attacks whose placement in each frame is set by timing nobody reports (a pulse phase, the moment the
    interference hits): a per-frame *latent*. Fits may register it on the fit frames (they are fit data). A held-out
    frame is scored by the likelihood of its pixels with the latent *marginalised* over the prior the fitted model
    gives it (``latent_candidates``: the possible values and their prior weights), never fitted on that frame:

        effective SSE = -2 s^2 log sum_k w_k exp(-SSE_k / (2 s^2)),

    with ``s^2`` the per-value residual variance of the fit frames (registered). It is the frame's Gaussian
    negative log-likelihood in squared-error units: the registered SSE plus the price of not knowing the latent
    (at most ``2 s^2 log K`` for K equally likely values), and exactly the SSE when the latent is known. The
    "registered" figure (latent fitted on each held-out frame) is reported next to it, for comparison only."""

    heldout_definition = (
        "predictive: each held-out frame's per-frame latent is marginalised over the prior of the model fitted on "
        "the fit frames (Gaussian likelihood with the fit frames' residual variance, expressed as an RMSE); the "
        "'registered' RMSE fits the latent on each held-out frame itself and is reported for comparison only"
    )

    def latent_candidates(self, fit: Fit, index: int) -> tuple[np.ndarray, np.ndarray]:
        """(SSE of pair ``index`` in [0, 1] units for every latent value the model allows, prior weights)."""
        raise NotImplementedError

    def registered_sse(self, fit: Fit, index: int) -> float:
        """SSE of pair ``index`` ([0, 1] units) with the latent fitted on the pair itself."""
        return float(self.latent_candidates(fit, index)[0].min())

    def predict_registered(self, fit: Fit, index: int) -> torch.Tensor:
        """The prediction with the latent fitted on the pair itself (figures, residual structure, noise)."""
        raise NotImplementedError

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        return self.predict_registered(fit, index)

    def noise_variance(self, fit: Fit, items: np.ndarray) -> float:
        """Per-value residual variance of the registered fit on ``items`` (fit frames)."""
        total, count = 0.0, 0
        for i in items:
            total += self.registered_sse(fit, int(i))
            count += 3 * self.pairs[int(i)].height * self.pairs[int(i)].width
        return max(total / max(count, 1), 1e-8)

    def effective_sse(self, fit: Fit, index: int) -> float:
        sse, weight = self.latent_candidates(fit, index)
        variance = fit.extra["noise_variance"]
        keep = weight > 0
        return float(-2.0 * variance * logsumexp(np.log(weight[keep]) - sse[keep] / (2.0 * variance)))

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        sq, counts = self.item_squared_errors(fit, items)
        return float(sq.sum()), int(counts.sum())

    def item_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        sq = np.array([255.0**2 * self.effective_sse(fit, int(i)) for i in items])
        counts = np.array([3.0 * self.pairs[int(i)].height * self.pairs[int(i)].width for i in items])
        return sq, counts

    def expected_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per-item squared error expected over the latent's prior (a point prediction made without the frame)."""
        sq = []
        for i in items:
            sse, weight = self.latent_candidates(fit, int(i))
            sq.append(255.0**2 * float(np.sum(weight * sse) / np.sum(weight)))
        counts = np.array([3.0 * self.pairs[int(i)].height * self.pairs[int(i)].width for i in items])
        return np.array(sq), counts

    def registered_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        sq = np.array([255.0**2 * self.registered_sse(fit, int(i)) for i in items])
        counts = np.array([3.0 * self.pairs[int(i)].height * self.pairs[int(i)].width for i in items])
        return sq, counts
