"""A ground-truth physical camera that renders synthetic "measured" frame pairs with chosen effects switched on.

Written independently of ``lerobot_phantom.transforms.physics`` (numpy + scipy.ndimage only) so that the
calibration tool is tested against a separate implementation of the physics, with randomised parameters and
procedurally generated scenes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image
from scipy import ndimage, optimize


def srgb_decode(v: np.ndarray) -> np.ndarray:
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def srgb_encode(v: np.ndarray) -> np.ndarray:
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.maximum(v, 0.0031308) ** (1 / 2.4) - 0.055)


def scene(rng: np.random.Generator, height: int, width: int, checkers: int = 0) -> np.ndarray:
    """A procedural scene (H, W, 3) in [0.05, 0.95]: a colour gradient, random boxes and discs, texture, and
    ``checkers`` high-contrast checkerboard patches (fine detail that blur visibly changes)."""
    ys, xs = np.mgrid[0:height, 0:width] / max(height, width)
    image = (
        rng.uniform(0.2, 0.7, 3)
        + rng.uniform(-0.3, 0.3, 3) * xs[..., None]
        + rng.uniform(-0.3, 0.3, 3) * ys[..., None]
    )
    for _ in range(rng.integers(4, 9)):
        colour = rng.uniform(0.05, 0.95, 3)
        cx, cy = rng.uniform(0, width), rng.uniform(0, height)
        size = rng.uniform(0.08, 0.3) * max(height, width)
        px, py = np.mgrid[0:height, 0:width][::-1]
        if rng.random() < 0.5:
            mask = (np.abs(px - cx) < size) & (np.abs(py - cy) < 0.6 * size)
        else:
            mask = (px - cx) ** 2 + (py - cy) ** 2 < size**2
        image[mask] = colour
    for _ in range(checkers):
        cell = int(rng.integers(2, 5))
        y0, x0 = int(rng.integers(0, height - 16)), int(rng.integers(0, width - 16))
        h, w = int(rng.integers(12, height // 2)), int(rng.integers(12, width // 2))
        py, px = np.mgrid[0:h, 0:w]
        board = ((py // cell + px // cell) % 2).astype(float)
        dark, light = rng.uniform(0.05, 0.3, 3), rng.uniform(0.7, 0.95, 3)
        image[y0 : y0 + h, x0 : x0 + w] = (dark + (light - dark) * board[..., None])[
            : height - y0, : width - x0
        ]
    for _ in range(3):
        fx, fy, phase = rng.uniform(2, 12), rng.uniform(2, 12), rng.uniform(0, 2 * np.pi)
        image += rng.uniform(0.02, 0.06) * np.sin(2 * np.pi * (fx * xs + fy * ys) + phase)[..., None]
    return np.clip(image, 0.05, 0.95)


READ_NOISE = 0.2 / 255.0  # sensor read noise, sd in linear light (full scale 1)


def save(
    path: Path, image: np.ndarray, rng: np.random.Generator, noise: float = READ_NOISE, shot: float = 0.0
) -> None:
    """The encoded ``image`` as a sensor records it: read noise (sd ``noise``) plus photon shot noise (variance
    ``shot`` x signal) added to the *linear* light (the image decoded as sRGB), before the tone curve, as a sensor
    adds them; then the sRGB curve and 8-bit quantisation."""
    linear = srgb_decode(np.clip(image, 0.0, 1.0))
    sd = np.sqrt(noise**2 + shot * linear)
    noisy = np.clip(linear + rng.normal(0.0, 1.0, image.shape) * sd, 0.0, 1.0)
    encoded = srgb_encode(noisy)
    Image.fromarray((encoded * 255).round().astype(np.uint8)).save(path)


def sizes(rng: np.random.Generator, n: int) -> list[tuple[int, int]]:
    return [(int(rng.integers(56, 72)), int(rng.integers(64, 84))) for _ in range(n)]


def write_table(folder: Path, rows: list[dict]) -> None:
    columns = list(rows[0])
    lines = [",".join(columns)] + [",".join(str(r[c]) for c in columns) for r in rows]
    (folder / "pairs.csv").write_text("\n".join(lines) + "\n")


# ---------------------------------------------------------------------------------------------------------------


def laser_pattern(rng: np.random.Generator, height: int, width: int) -> tuple[np.ndarray, tuple, np.ndarray]:
    """A laser's light (no scene), linear and unclipped: a coloured spot that saturates a capture; returns (light,
    centre, laser colour)."""
    colour = np.array(rng.permutation([1.0, rng.uniform(0.05, 0.3), rng.uniform(0.05, 0.3)]))
    cx, cy = rng.uniform(0.3, 0.7) * width, rng.uniform(0.3, 0.7) * height
    sigma = rng.uniform(0.06, 0.12) * max(height, width)
    ys, xs = np.mgrid[0:height, 0:width]
    irradiance = rng.uniform(2.0, 6.0) * np.exp(-((xs - cx) ** 2 + (ys - cy) ** 2) / (2 * sigma**2))
    return irradiance[..., None] * colour, (cx, cy), colour


def metered_exposure(blinded: np.ndarray, clean: np.ndarray) -> float:
    """The library's auto-exposure meter (``frame_models/laser_blinding.py``): the exposure ``k`` at which the
    blinded frame's clipped mean level (channel means, clipped at white) equals the clean frame's."""
    level, target = blinded.mean(-1), np.minimum(clean.mean(-1), 1.0).mean()
    return optimize.brentq(lambda k: np.minimum(k * level, 1.0).mean() - target, 1e-4, 10.0)


def render_laser_blinding(folder: Path, effects: set[str], seed: int, n_pairs: int = 10) -> dict:
    rng = np.random.default_rng(seed)
    truth = {
        "alpha": rng.uniform(0.4, 0.8),
        "gain": rng.uniform(0.6, 1.5),
        "halo_amplitude": rng.uniform(0.3, 0.6),
        "halo_exponent": rng.uniform(1.5, 2.5),
        "halo_scale": rng.uniform(10.0, 25.0),
        "auto_exposure": rng.uniform(0.7, 1.5),  # power of the meter's exposure (1: a uniform meter)
    }
    glare = "halo_power_law" in effects
    # frames' own exposures are rendered with the beam-profile capture too: with the plain case's capture, whose
    # clipped core lights the frames flat, the core's width sits at its bound and linear light is never named
    attenuated = glare or "frame_exposure" in effects
    if attenuated:
        # the glare is the laser's light, so the capture records it too; a beam profile is captured through an
        # attenuator (tens of times weaker than the attack), where the glare far from the spot sinks below the
        # capture's 8-bit floor while the frames show it. Drawn apart, so the other draws stay as they were
        truth["gain"] *= np.random.default_rng([seed, 1]).uniform(20.0, 60.0)
    # frame_exposure: each frame's laser light times exp(spread z), drawn apart so the other draws stay as they were
    exposure_rng = np.random.default_rng([seed, 2])
    truth["exposure_spread"] = exposure_rng.uniform(0.3, 0.6)
    rows = []
    for i, (height, width) in enumerate(sizes(rng, n_pairs)):
        clean = scene(rng, height, width)
        laser, (cx, cy), colour = laser_pattern(rng, height, width)
        if glare:
            ys, xs = np.mgrid[0:height, 0:width]
            r = np.hypot(xs - cx, ys - cy) * 256 / max(height, width)
            halo = truth["halo_amplitude"] * (1 + r / truth["halo_scale"]) ** -truth["halo_exponent"]
            laser = laser + halo[..., None] * colour / truth["gain"]
        pattern = srgb_encode(laser)
        s = rng.uniform(0.3, 1.0)
        frame_log_exposure = truth["exposure_spread"] * exposure_rng.standard_normal()
        s_light = s * np.exp(frame_log_exposure) if "frame_exposure" in effects else s
        truth.setdefault("frame_log_exposure", []).append(
            frame_log_exposure if "frame_exposure" in effects else 0.0
        )
        linear = "linear_light_saturation" in effects
        decode = srgb_decode if linear else (lambda v: v)
        encode = srgb_encode if linear else (lambda v: np.clip(v, 0, 1))
        x, p = decode(clean), decode(pattern)
        if (
            attenuated
        ):  # the attack's power lights the frames with the whole beam and glare, not the capture's
            light, weight = s_light * truth["gain"] * laser, 1.0
        elif linear:
            light, weight = s_light * truth["gain"] * p, 1.0
        else:
            light, weight = truth["alpha"] * s * p, 1.0 - truth["alpha"] * s
        total = weight * x + light
        if "auto_exposure" in effects:
            total = total * metered_exposure(total, x) ** truth["auto_exposure"]
        attacked = encode(np.clip(total, 0, 1))
        for name, image in (("clean", clean), ("attacked", attacked), ("pattern", pattern)):
            save(folder / f"{name}_{i}.png", image, rng, noise=0.0 if name == "pattern" else READ_NOISE)
        rows.append(
            {
                "clean": f"clean_{i}.png",
                "attacked": f"attacked_{i}.png",
                "pattern": f"pattern_{i}.png",
                "intensity": round(s, 4),
            }
        )
    write_table(folder, rows)
    return truth


def projected_image(rng: np.random.Generator, height: int, width: int) -> np.ndarray:
    """What an attacker projects: bold coloured blocks on black."""
    image = np.zeros((height, width, 3))
    for _ in range(rng.integers(3, 7)):
        y0, x0 = rng.integers(0, height - 8), rng.integers(0, width - 8)
        image[y0 : y0 + rng.integers(8, height // 2), x0 : x0 + rng.integers(8, width // 2)] = rng.choice(
            [0.0, 0.5, 1.0], 3
        )
    return image


def render_light_projection(folder: Path, effects: set[str], seed: int, n_pairs: int = 10) -> dict:
    rng = np.random.default_rng(seed)
    crosstalk = np.eye(3) * rng.uniform(0.5, 0.8) + rng.uniform(0.1, 0.3, (3, 3)) * (1 - np.eye(3))
    truth = {
        "opacity": rng.uniform(0.3, 0.6),
        "strength": rng.uniform(0.4, 0.8),
        "crosstalk": crosstalk,
        "floor": rng.uniform(0.1, 0.3),
    }
    rows = []
    for i, (height, width) in enumerate(sizes(rng, n_pairs)):
        clean = scene(rng, height, width)
        projected = projected_image(rng, height, width)
        s = rng.uniform(0.4, 1.0)
        light = projected @ crosstalk.T if "channel_crosstalk" in effects else projected
        if "additive_light" in effects:
            light = s * light * (1.0 if "channel_crosstalk" in effects else truth["strength"])
            if "albedo_modulation" in effects:
                light = light * (clean + truth["floor"])
            attacked = clean + light
        else:
            attacked = (1 - truth["opacity"] * s) * clean + truth["opacity"] * s * light
        for name, image in (("clean", clean), ("attacked", np.clip(attacked, 0, 1)), ("pattern", projected)):
            save(folder / f"{name}_{i}.png", image, rng, noise=0.0 if name == "pattern" else READ_NOISE)
        rows.append(
            {
                "clean": f"clean_{i}.png",
                "attacked": f"attacked_{i}.png",
                "pattern": f"pattern_{i}.png",
                "intensity": round(s, 4),
                # the projected light is the pattern's own values, as the scene's light is the clean frame's
                "pattern_record": "captured",
            }
        )
    write_table(folder, rows)
    return truth


def motion_blur(image: np.ndarray, dx: float, dy: float, positions: np.ndarray) -> np.ndarray:
    height, width, _ = image.shape
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float64)
    out = np.zeros_like(image)
    for t in positions:
        coords = [ys + t * dy, xs + t * dx]
        for c in range(3):
            out[..., c] += ndimage.map_coordinates(image[..., c], coords, order=1, mode="nearest")
    return out / len(positions)


def render_ultrasound_blur(folder: Path, effects: set[str], seed: int, n_pairs: int = 10) -> dict:
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, np.pi)
    length = rng.uniform(36.0, 56.0)  # pixels at full intensity on the 256-pixel reference scale
    truth = {"angle": angle, "length": length}
    phases = (np.arange(200) + 0.5) / 200
    positions = 0.5 * np.sin(2 * np.pi * phases) if "sinusoidal_motion" in effects else phases - 0.5
    rows = []
    for i, (height, width) in enumerate(sizes(rng, n_pairs)):
        clean = scene(rng, height, width, checkers=3)
        s = rng.uniform(0.5, 1.0)
        pixels = s * length * max(height, width) / 256
        attacked = motion_blur(clean, pixels * np.cos(angle), pixels * np.sin(angle), positions)
        save(folder / f"clean_{i}.png", clean, rng)
        save(folder / f"attacked_{i}.png", attacked, rng)
        rows.append({"clean": f"clean_{i}.png", "attacked": f"attacked_{i}.png", "intensity": round(s, 4)})
    write_table(folder, rows)
    return truth


def render_em_color_strip(folder: Path, effects: set[str], seed: int, n_pairs: int = 10) -> dict:
    rng = np.random.default_rng(seed)
    gain, offset = rng.uniform(1.3, 2.5), rng.uniform(0.0, 0.2)
    period = rng.uniform(0.15, 0.4)
    truth = {"gain": gain, "offset": offset, "period": period}
    rows = []
    for i, (height, width) in enumerate(sizes(rng, n_pairs)):
        clean = scene(rng, height, width)
        r = np.arange(height)
        if "bayer_phase_flip" in effects:
            mask = r >= rng.integers(int(0.2 * height), int(0.8 * height))
        else:
            mask = np.remainder(r - rng.uniform(0, period * height), period * height) < 0.5 * period * height
        swapped = np.clip(gain * clean[..., 1], 0, 1)
        mixed = np.clip(0.5 * (clean[..., 0] + clean[..., 2]) - offset, 0, 1)
        wrong = np.stack([swapped, mixed, swapped], axis=-1)
        attacked = np.where(mask[:, None, None], wrong, clean)
        save(folder / f"clean_{i}.png", clean, rng)
        save(folder / f"attacked_{i}.png", attacked, rng)
        rows.append({"clean": f"clean_{i}.png", "attacked": f"attacked_{i}.png"})
    write_table(folder, rows)
    return truth


def render_em_truncation(
    folder: Path, effects: set[str], seed: int, n_pairs: int = 10, shot: float = 0.0, dim: float = 1.0
) -> dict:
    """Rows lost from the frame buffer: ``num`` rows from ``start`` vanish, the rest moves up, the tail repeats.
    The paper ties the start to the count (``start = num``); ``free_band_position`` draws it anywhere.
    ``shot``: photon shot-noise variance per unit signal; ``dim`` < 1: each pair is exposed at a random level
    in [dim, 1] (dark and bright captures)."""
    rng = np.random.default_rng(seed)
    truth = {"ratio_per_intensity": rng.uniform(0.15, 0.3)}
    rows = []
    for i, (height, width) in enumerate(sizes(rng, n_pairs)):
        clean = scene(rng, height, width) * (rng.uniform(dim, 1.0) if dim < 1.0 else 1.0)
        s = rng.uniform(0.4, 1.0)
        num = max(2, int(height * truth["ratio_per_intensity"] * s))
        if "free_band_position" in effects:
            start = int(rng.integers(0, height - 2 * num + 1))
        else:
            start = max(0, min(num, height - 2 * num))
        source = np.arange(height)
        moved = (source >= start) & (source < height - num)
        attacked = clean[np.where(moved, source + num, source)]
        save(folder / f"clean_{i}.png", clean, rng, shot=shot)
        save(folder / f"attacked_{i}.png", attacked, rng, shot=shot)
        rows.append({"clean": f"clean_{i}.png", "attacked": f"attacked_{i}.png", "intensity": round(s, 4)})
    write_table(folder, rows)
    return truth


def paper_strip_profile(height: int, width: int) -> np.ndarray:
    """The paper's band weight (grey levels per unit strength) over the whole frame: zero outside rows
    h//3 .. 2 (h//3), a Gaussian centred h/2 below the band start and at mid-width (sigma h/2, w/4)."""
    start, end = height // 3, (height // 3) * 2
    p, q = np.mgrid[0:height, 0:width].astype(np.float64)
    sigma_p, sigma_q = height / 2.0, width / 4.0
    gauss = np.exp(-0.5 * ((p - start - sigma_p) ** 2 / sigma_p**2 + (q - width / 2.0) ** 2 / sigma_q**2))
    profile = gauss * height * width / (2 * np.pi * sigma_p * sigma_q)
    profile[(p < start) | (p >= end)] = 0.0
    return profile


def stripe_rows(height: int, on: float, window: float, phase: float, period: float | None) -> np.ndarray:
    """Lit share of each row of a rolling shutter (row r exposed during [r + phase, r + phase + window], in
    rows) under a laser on during [k period, k period + on]: the overlap, over its largest possible value."""
    starts = np.arange(height) + phase
    pulses = [0.0] if period is None else np.arange(-2, height / period + 3) * period
    lit = np.zeros(height)
    for pulse in pulses:
        lit += np.clip(np.minimum(starts + window, pulse + on) - np.maximum(starts, pulse), 0.0, None)
    return np.clip(lit / min(on, window), 0.0, 1.0)


def render_laser_color_strip(folder: Path, effects: set[str], seed: int, n_pairs: int = 10) -> dict:
    """Without effects: the paper's band. ``exposure_overlap``: a stripe across the width wherever the pulse
    falls; with ``stripe_period`` it repeats; with ``sensor_gamma`` its light adds to the scene's in linear light
    under a power-law tone curve (the exponent drawn from its own generator, so the other draws stay as they were)."""
    rng = np.random.default_rng(seed)
    gamma = np.random.default_rng([seed, 2]).uniform(1.8, 2.6) if "sensor_gamma" in effects else 1.0
    colour = np.array(rng.permutation([1.0, rng.uniform(0.05, 0.3), rng.uniform(0.05, 0.3)]))
    truth = {
        "strength": rng.uniform(150.0, 300.0),  # paper units (grey levels x 1000 / weight)
        "peak": rng.uniform(0.3, 0.5),
        "on_share": rng.uniform(0.06, 0.12),
        "exposure_share": rng.uniform(0.03, 0.08),
        "period_share": rng.uniform(0.35, 0.5),
        "gamma": gamma,
    }
    rows = []
    for i, (height, width) in enumerate(sizes(rng, n_pairs)):
        clean = scene(rng, height, width)
        s = rng.uniform(0.5, 1.0)
        if "exposure_overlap" in effects:
            period = truth["period_share"] * height if "stripe_period" in effects else None
            # the stripe sits at rows -phase - window .. -phase + on
            phase = -rng.uniform(0.1, 0.8) * height if period is None else rng.uniform(0, period)
            light = stripe_rows(
                height, truth["on_share"] * height, truth["exposure_share"] * height, phase, period
            )
            added = s * truth["peak"] * light[:, None, None] * colour
        else:
            added = s * truth["strength"] * paper_strip_profile(height, width)[..., None] * colour / 255.0
        attacked = np.clip(clean**gamma + added, 0.0, 1.0) ** (1.0 / gamma)
        save(folder / f"clean_{i}.png", clean, rng)
        save(folder / f"attacked_{i}.png", attacked, rng)
        rows.append({"clean": f"clean_{i}.png", "attacked": f"attacked_{i}.png", "intensity": round(s, 4)})
    write_table(folder, rows)
    return truth


RENDERERS = {
    "laser_color_strip": render_laser_color_strip,
    "em_truncation": render_em_truncation,
    "laser_blinding": render_laser_blinding,
    "light_projection": render_light_projection,
    "ultrasound_blur": render_ultrasound_blur,
    "em_color_strip": render_em_color_strip,
}


def projection_pairs_with_spread_light(spread_px: float, seed: int = 0) -> list:
    """Light projection pairs whose projected light reaches the sensor blurred by ``spread_px`` (a Gaussian), where
    the recorded pattern is the sharp frame the projector was sent; encoded values add (no tone curve), so
    additive light at the true strength leaves only the spread light and a little noise. The blur is scipy's, not
    the package's."""
    import torch

    from lerobot_phantom.calibration.frame_models.common import Pair

    rng = np.random.default_rng(seed)
    pairs = []
    for index in range(6):
        clean = ndimage.gaussian_filter(rng.uniform(0.1, 0.5, (3, 40, 50)), sigma=(0, 4, 4))
        pattern = np.zeros((3, 40, 50))
        for _ in range(3):
            top, left = rng.integers(0, 30), rng.integers(0, 40)
            pattern[rng.integers(3), top : top + 10, left : left + 10] = 1.0
        light = ndimage.gaussian_filter(pattern, sigma=(0, spread_px, spread_px)) if spread_px else pattern
        attacked = clean + 0.4 * light + rng.normal(0.0, 0.004, clean.shape)
        pairs.append(
            Pair(f"p{index}", *(torch.from_numpy(a) for a in (clean, attacked.clip(0, 1), pattern)), 1.0)
        )
    return pairs


def assert_kept_values_change_no_prediction(
    kept, fresh, memo: str, effects: frozenset[str], feats: dict
) -> list[dict]:
    """A frame problem's values kept between the columns of a finite-difference Jacobian (its ``memo``) change no
    prediction: along a path through every parameter of ``effects`` (each moved once from its start value, then all
    back), ``kept``'s predictions at ``feats`` equal ``fresh``'s, whose memo is cleared at every step. The path."""
    import torch

    point = {spec.name: spec.init for spec in kept.param_specs(effects)}
    steps = [point] + [{**point, name: value * 1.01 + 1e-3} for name, value in point.items()] + [point]
    with torch.no_grad():
        for params in steps:
            values = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
            getattr(fresh, memo).clear()
            torch.testing.assert_close(
                kept.predict_features(effects, values, feats),
                fresh.predict_features(effects, values, feats),
                rtol=0,
                atol=0,
            )
    return steps


def blurred_by_the_attack(options: dict, problem, index: int):
    """Pair ``index``'s clean frame as ``UltrasoundBlur(**options)`` blurs it at the pair's intensity, through the
    attack's own sampler: what a user of ``calibrated.json`` (its ``kwargs``: ``options``) gets."""
    from lerobot_phantom.transforms.ultrasound_blur import UltrasoundBlur

    pair = problem.pairs[index]
    return UltrasoundBlur(pair.intensity, **options)(pair.clean.unsqueeze(0))[0]
