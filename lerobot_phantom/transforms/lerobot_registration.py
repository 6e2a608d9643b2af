"""Make LeRobot's image-transform config accept the camera attacks and ``PhantomMix`` by class name.

After ``register_image_transforms()`` (called by ``lerobot_phantom.register()``, which LeRobot's plugin discovery,
the ``lerobot-phantom-*`` scripts or the user run), a LeRobot dataset config can name an attack like any
torchvision transform::

    "image_transforms": {"enable": true, "max_num_transforms": 1,
                         "tfs": {"laser": {"type": "LaserBlinding", "kwargs": {"intensity": "medium"}}}}

and ``ImageTransforms`` / ``lerobot.datasets.factory.make_dataset`` build ``LaserBlinding(intensity="medium")``;
``{"type": "PhantomMix", "kwargs": {"rate": 0.3}}`` mixes attacks as ``--phantom.*`` does (``transforms.mixing``).
Class names resolve through the attack registry at build time (an attack module is imported only when a config
names it); instruction attacks are not image transforms and are not accepted. How LeRobot is hooked lives in
``lerobot_phantom._lerobot_compat`` (transforms section).
"""

from __future__ import annotations

import importlib

from lerobot_phantom import _lerobot_compat
from lerobot_phantom.transforms.registry import (
    _CLASS_PATHS,
    CAMERA_ATTACKS,
    attack_name_of_class,
    get_attack_class,
)

MIXING_TRANSFORMS: dict[str, str] = {"PhantomMix": "lerobot_phantom.transforms.mixing"}
"""Image-transform types that are not single attacks: class name -> module."""


def camera_attack_class_names() -> dict[str, str]:
    """Class name -> registry name of every camera attack (``"LaserBlinding"`` -> ``"laser_blinding"``)."""
    return {_CLASS_PATHS[name].split(":")[1]: name for name in CAMERA_ATTACKS}


def resolve_camera_attack(type_name: str) -> type | None:
    """The camera attack or mixing class named ``type_name`` (class name as in a LeRobot config), or None."""
    if type_name in MIXING_TRANSFORMS:
        return getattr(importlib.import_module(MIXING_TRANSFORMS[type_name]), type_name)
    name = attack_name_of_class(type_name)
    if name is None or name not in CAMERA_ATTACKS:
        return None
    return get_attack_class(name)


def register_image_transforms() -> str:
    """Register every camera attack with LeRobot's image transforms; idempotent. Returns how ("wrapped"/"table")."""
    classes: dict[str, type] = {}
    if _lerobot_compat.image_transforms_module().__dict__.get("_CUSTOM_TRANSFORMS") is not None:
        # A table needs the classes themselves, so every attack module is imported here.
        classes = {cls_name: get_attack_class(name) for cls_name, name in camera_attack_class_names().items()}
        classes.update({cls_name: resolve_camera_attack(cls_name) for cls_name in MIXING_TRANSFORMS})
    return _lerobot_compat.register_image_transform_types(resolve_camera_attack, classes)
