"""The one registry of attacks: name -> class, and ``make_attack``.

Integer ids (``ATTACK_IDS``) are stable and used as the ``phantom.attack`` label of attacked samples (-1 = clean).
"""

from __future__ import annotations

import importlib
from typing import Any

CAMERA_ATTACKS: tuple[str, ...] = (
    "laser_blinding",
    "light_projection",
    "laser_color_strip",
    "em_color_strip",
    "em_truncation",
    "ultrasound_blur",
)
INSTRUCTION_ATTACKS: tuple[str, ...] = ("voice_dos", "voice_spoofing")
ATTACK_NAMES: tuple[str, ...] = CAMERA_ATTACKS + INSTRUCTION_ATTACKS
ATTACK_IDS: dict[str, int] = {name: i for i, name in enumerate(ATTACK_NAMES)}
CLEAN_ID = -1

_CLASS_PATHS: dict[str, str] = {
    "laser_blinding": "lerobot_phantom.transforms.laser_blinding:LaserBlinding",
    "light_projection": "lerobot_phantom.transforms.light_projection:LightProjection",
    "laser_color_strip": "lerobot_phantom.transforms.laser_color_strip:LaserColorStrip",
    "em_color_strip": "lerobot_phantom.transforms.em_color_strip:EMColorStrip",
    "em_truncation": "lerobot_phantom.transforms.em_truncation:EMTruncation",
    "ultrasound_blur": "lerobot_phantom.transforms.ultrasound_blur:UltrasoundBlur",
    "voice_dos": "lerobot_phantom.transforms.instruction:VoiceDoS",
    "voice_spoofing": "lerobot_phantom.transforms.instruction:VoiceSpoofing",
}


def check_attack_name(name: str) -> str:
    if name not in _CLASS_PATHS:
        raise ValueError(f"unknown attack {name!r}; valid attacks: {', '.join(ATTACK_NAMES)}")
    return name


def get_attack_class(name: str) -> type:
    module_name, class_name = _CLASS_PATHS[check_attack_name(name)].split(":")
    return getattr(importlib.import_module(module_name), class_name)


def attack_name_of_class(class_name: str) -> str | None:
    """Registry name for a class name (``"LaserBlinding"`` -> ``"laser_blinding"``), or None."""
    for name, path in _CLASS_PATHS.items():
        if path.split(":")[1] == class_name:
            return name
    return None


def is_camera_attack(name: str) -> bool:
    return check_attack_name(name) in CAMERA_ATTACKS


def make_attack(
    name: str, intensity: Any = "medium", *, calibration: str | None = None, **kwargs: Any
) -> Any:
    """Build attack ``name`` at ``intensity``; ``calibration`` is a directory (or set) that must calibrate it."""
    cls = get_attack_class(name)
    if calibration is not None:
        from lerobot_phantom.transforms.calibrated import calibrated_kwargs

        kwargs = {**calibrated_kwargs(name, calibration), **kwargs}
    return cls(intensity=intensity, **kwargs)


def make_attacks(names: Any, intensity: Any = "medium", *, calibration: str | None = None) -> dict[str, Any]:
    """Build every attack in ``names`` (order kept, duplicates dropped), e.g. for mixing them in training.

    ``calibration`` (a calibration directory or set, see ``transforms.calibrated``) gives the measured physics to
    the attacks it calibrates; the others keep the paper's formulas.
    """
    from lerobot_phantom.transforms.calibrated import calibrated_options

    options = calibrated_options(names, calibration)
    return {
        name: make_attack(name, intensity=intensity, **options.get(name, {})) for name in dict.fromkeys(names)
    }
