"""The attacks as plain functions, for users outside torchvision: tensor in, tensor out, explicit physical
parameters (a float, or one value per image of a batch).

Images are uint8 (0-255) or float (0-1) tensors, ``(C, H, W)`` or ``(..., C, H, W)`` with C in {1, 3, 4}; every
function returns the input's dtype, shape and device. Parameters are in pixels of the image you pass (the
transforms' 256x256 reference scaling is not applied here). Each kernel lives beside its transform class and
implements the paper's Appendix A algorithm with the fixes listed in that module's docstring:

===================== ===================================================================== =====================
attack                function                                                              paper levels (w/m/s)
===================== ===================================================================== =====================
laser blinding        ``laser_blinding(image, alpha, pattern)``                             alpha 0.1 / 0.5 / 0.9
light projection      ``light_projection(image, pattern_rgba, transparency, x_off, y_off)``  t 0.1 / 0.5 / 0.9
laser color strip     ``laser_color_strip(image, strength, color_fractions)``               S 500 / 1500 / 2500
EM color strip        ``em_color_strip(image, num_stripes, band_fraction=1, ...)``           N 8 / 12 / 16
EM truncation         ``em_truncation(image, ratio)``                                       r 0.1 / 0.2 / 0.3
ultrasound blur       ``ultrasound_blur(image, dx, dy, theta_deg=0, scale=0)``              dx = dy 5 / 10 / 20
===================== ===================================================================== =====================

``laser_glare`` (the default red laser glare, statistics of the authors' ``red.png``), ``laser_spot`` (a small spot)
and ``projection_shape`` (the default ``"can"``, 50x42 like the authors' ``can.png``, and other shapes) build the
procedural patterns the first two take; ``laser_blinding`` resizes a pattern to the image with PIL's LANCZOS filter
as the authors do, ``light_projection`` pastes it at its own size. ``apply_attack`` is the
one-call version of a transform (registry name, intensity, seed), and ``voice_dos`` / ``voice_spoofing`` apply the
instruction attacks to a task string or a list of them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import torch

from lerobot_phantom.transforms.em_color_strip import em_color_strip
from lerobot_phantom.transforms.em_truncation import em_truncation
from lerobot_phantom.transforms.intensity import IntensitySpec
from lerobot_phantom.transforms.laser_blinding import laser_blinding
from lerobot_phantom.transforms.laser_color_strip import laser_color_strip
from lerobot_phantom.transforms.light_projection import light_projection
from lerobot_phantom.transforms.patterns import laser_glare, laser_spot, projection_shape
from lerobot_phantom.transforms.registry import is_camera_attack, make_attack
from lerobot_phantom.transforms.ultrasound_blur import ultrasound_blur

__all__ = [
    "apply_attack",
    "em_color_strip",
    "em_truncation",
    "laser_blinding",
    "laser_color_strip",
    "laser_glare",
    "laser_spot",
    "light_projection",
    "projection_shape",
    "ultrasound_blur",
    "voice_dos",
    "voice_spoofing",
]


def _generator(seed: int | None, generator: torch.Generator | None) -> torch.Generator:
    if generator is not None and seed is not None:
        raise ValueError("pass either seed= or generator=, not both")
    return generator if generator is not None else torch.Generator().manual_seed(0 if seed is None else seed)


def apply_attack(
    image: torch.Tensor | str | Sequence[str],
    name: str,
    intensity: IntensitySpec | torch.Tensor = "medium",
    *,
    seed: int | None = None,
    generator: torch.Generator | None = None,
    return_params: bool = False,
    **attack_kwargs: Any,
) -> Any:
    """Apply registry attack ``name`` once, with parameters drawn from ``generator`` (or ``seed``, default 0).

    Camera attacks take an image tensor (a batch gets per-sample parameters when the intensity is a range or a
    per-sample tensor); instruction attacks take a task string or a list of them. ``attack_kwargs`` go to the
    attack's constructor. With ``return_params=True`` returns ``(output, params)``.
    """
    override = intensity if isinstance(intensity, torch.Tensor) else None
    # a per-sample tensor overrides at sampling time; the constructor only needs some valid spec
    attack = make_attack(name, intensity="medium" if override is not None else intensity, **attack_kwargs)
    rng = _generator(seed, generator)
    if is_camera_attack(name):
        if not isinstance(image, torch.Tensor):
            raise TypeError(f"camera attack {name!r} needs an image tensor, got {type(image).__name__}")
        batch = 1 if image.ndim <= 3 else int(torch.tensor(image.shape[:-3]).prod())
        params = attack.sample_params(
            batch, *image.shape[-2:], intensity=override, generator=rng, device=image.device
        )
        out = attack.apply_params(image, params)
    else:
        single = isinstance(image, str)
        tasks = [image] if single else list(image)
        params = attack.sample_params(len(tasks), intensity=override, generator=rng)
        out = attack.apply_params(tasks, params)
        out = out[0] if single else out
    return (out, params) if return_params else out


def voice_dos(
    task: str | Sequence[str], intensity: IntensitySpec = "strong", *, seed: int | None = None, **kwargs: Any
) -> str | list[str]:
    """Voice DoS on a task (or a list): the paper empties the instruction; see ``instruction.VoiceDoS``."""
    return apply_attack(task, "voice_dos", intensity, seed=seed, **kwargs)


def voice_spoofing(
    task: str | Sequence[str], intensity: IntensitySpec = "strong", *, seed: int | None = None, **kwargs: Any
) -> str | list[str]:
    """Voice spoofing on a task (or a list): the paper appends a command; see ``instruction.VoiceSpoofing``."""
    return apply_attack(task, "voice_spoofing", intensity, seed=seed, **kwargs)
