"""Effects the library has no form for, rendered by the independent camera simulator (tests/calibration/camsim.py)
and calibrated: what does the tool name, and does it report the structure left?

Blur forms (integrated in linear irradiance before the sensor, like camsim's sinusoidal case): a defocus disc (2-D,
no path), a centred triangle-wave path (uniform dwell, not arcsine), a sinusoid of 1.2-2.8 cycles per exposure (the
library's sinusoidal path assumes many), and a two-axis (elliptical) resonance. On the paper's digital forms (the
null cases' renders): a grey-world white balance answering the projected colour (light projection), and a lens-flare
ghost of the laser's light mirrored through the frame's centre (laser blinding).

Usage: PYTHONPATH=. python docs/bench/session82/out_of_library_probe.py FORM[,FORM...] SEED... (FORM "all": every one)
"""

import dataclasses
import os
import sys
import time

sys.path[:0] = ["tests/calibration", "tests"]
os.environ.setdefault("CAMSIM_SEED", "0")  # read at import; each draw here is seeded by its own SEED
os.environ.setdefault("HF_HUB_OFFLINE", "1")

import camsim as cs  # noqa: E402
import numpy as np  # noqa: E402
from test_independent_sim import N_PAIRS, named_causes, random_camera, unexplained_structure  # noqa: E402

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate  # noqa: E402


def blur_offsets(form: str, rng: np.random.Generator, d: float, unit: np.ndarray) -> np.ndarray:
    """(dy, dx) positions of the image during the exposure, for a path of extent ``d`` px along ``unit``."""
    t = (np.arange(96) + 0.5) / 96
    if form == "blur_disc":
        n = 144  # a sunflower lattice: uniform over the disc of diameter d
        radius, angle = np.sqrt((np.arange(n) + 0.5) / n), np.arange(n) * 2.399963
        return np.stack([radius * np.sin(angle), radius * np.cos(angle)], 1) * d / 2
    if form == "blur_triangle":
        wave = 2 * np.abs(((rng.uniform(5.2, 8.8) * t + rng.uniform(0, 1)) % 1.0) - 0.5) - 0.5
        return (d * wave)[:, None] * unit
    if form == "blur_few_cycles":
        wave = 0.5 * np.sin(2 * np.pi * rng.uniform(1.2, 2.8) * t + rng.uniform(0, 2 * np.pi))
        return (d * wave)[:, None] * unit
    if form == "blur_ellipse":
        phase = 2 * np.pi * rng.uniform(5.2, 8.8) * t + rng.uniform(0, 2 * np.pi)
        across = np.array([unit[1], -unit[0]])
        return (d / 2) * np.sin(phase)[:, None] * unit + (d / 4) * np.cos(phase)[:, None] * across
    raise ValueError(f"blur form {form!r}")


def blur_pairs(form: str, rng: np.random.Generator, cam: cs.Camera) -> list[cs.FramePair]:
    """camsim's ultrasound blur scenes (checkered, 0.3-1.0 intensities, 8-14 px at full intensity), blurred by
    ``form`` in linear irradiance."""
    direction = rng.uniform(0, np.pi)
    unit = np.array([np.sin(direction), np.cos(direction)])
    amplitude = rng.uniform(8, 14)
    session = cs.Session(cam)
    pairs = []
    for intensity in cs.intensities(rng, N_PAIRS, 0.3, 1.0):
        reflectance, light = cs.scene(rng, cam)
        block = rng.uniform(4, 7)
        yy, xx = np.mgrid[0 : cam.height, 0 : cam.width]
        reflectance = reflectance * np.where((yy // block + xx // block) % 2 == 0, 1.0, 0.4)[..., None]
        clean, exposure = session.clean(reflectance * light, rng)
        offsets = blur_offsets(form, rng, intensity * amplitude, unit)
        attacked, _ = cs.capture(cs.path_blur(reflectance * light, offsets), cam, rng, exposure=exposure)
        pairs.append(
            cs.FramePair(cs.encode(clean, cam), cs.encode(cs.quantised(attacked), cam), float(intensity))
        )
    return pairs


def white_balanced(pair: cs.FramePair, rng: np.random.Generator) -> cs.FramePair:
    attacked = pair.attacked.astype(float) / 255
    means = attacked.reshape(-1, 3).mean(0)
    gains = (means.mean() / means) ** rng.uniform(0.5, 1.0)
    return dataclasses.replace(
        pair, attacked=np.round(np.clip(attacked * gains, 0, 1) * 255).astype(np.uint8)
    )


def ghosted(pair: cs.FramePair, rng: np.random.Generator) -> cs.FramePair:
    light = np.clip(pair.attacked.astype(float) - pair.clean.astype(float), 0, None)
    ghost = rng.uniform(0.15, 0.3) * light[::-1, ::-1]
    return dataclasses.replace(
        pair, attacked=np.round(np.clip(pair.attacked + ghost, 0, 255)).astype(np.uint8)
    )


BLUR_FORMS = ("blur_disc", "blur_triangle", "blur_few_cycles", "blur_ellipse")
FORMS = {
    **{
        form: ("ultrasound_blur", lambda rng, cam, form=form: blur_pairs(form, rng, cam))
        for form in BLUR_FORMS
    },
    "projection_white_balance": (
        "light_projection",
        lambda rng, cam: [
            white_balanced(p, rng)
            for p in cs.light_projection_pairs(rng, cam, N_PAIRS, digital_alpha=rng.uniform(0.3, 0.6))
        ],
    ),
    "blinding_flare_ghost": (
        "laser_blinding",
        lambda rng, cam: [
            ghosted(p, rng)
            for p in cs.laser_blinding_pairs(rng, cam, N_PAIRS, digital_alpha=rng.uniform(0.4, 0.8))
        ],
    ),
}


def main(forms: list[str], seeds: list[int], root: str) -> None:
    for form in forms:
        attack, render = FORMS[form]
        for seed in seeds:
            started = time.process_time()
            rng = np.random.default_rng(seed)
            cam = random_camera(rng)
            folder = f"{root}/{form}_{seed}"
            cs.write_pairs(f"{folder}/pairs", render(rng, cam))
            report = calibrate(
                CalibrateConfig(
                    attack=attack, measured=f"{folder}/pairs", out=f"{folder}/out", seed=seed % 2**31
                )
            )
            structure = unexplained_structure(report)
            print(
                f"{form} seed {seed} ({cam.tone} tone): named {sorted(named_causes(report)) or 'nothing'}; "
                f"structure: {structure if structure else 'none reported'} "
                f"[{time.process_time() - started:.0f} s CPU]",
                flush=True,
            )


if __name__ == "__main__":
    chosen = list(FORMS) if sys.argv[1] == "all" else sys.argv[1].split(",")
    main(chosen, [int(s) for s in sys.argv[2:]], os.environ.get("PROBE_ROOT", "/tmp/out_of_library_probe"))
