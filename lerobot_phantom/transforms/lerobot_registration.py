"""Make LeRobot's image-transform config accept the camera attacks by class name.

After ``register_image_transforms()`` (called by ``lerobot_phantom.register()`` on import), a LeRobot dataset config
can name an attack like any torchvision transform::

    "image_transforms": {"enable": true, "max_num_transforms": 1,
                         "tfs": {"laser": {"type": "LaserBlinding", "kwargs": {"intensity": "medium"}}}}

and ``ImageTransforms`` / ``lerobot.datasets.factory.make_dataset`` build ``LaserBlinding(intensity="medium")``.
Class names resolve through the attack registry at build time (an attack module is imported only when a config
names it); instruction attacks are not image transforms and are not accepted. How LeRobot is hooked lives in
``lerobot_phantom._lerobot_compat`` (transforms section).
"""

from __future__ import annotations

from lerobot_phantom import _lerobot_compat
from lerobot_phantom.transforms.registry import (
    _CLASS_PATHS,
    CAMERA_ATTACKS,
    attack_name_of_class,
    get_attack_class,
)


def camera_attack_class_names() -> dict[str, str]:
    """Class name -> registry name of every camera attack (``"LaserBlinding"`` -> ``"laser_blinding"``)."""
    return {_CLASS_PATHS[name].split(":")[1]: name for name in CAMERA_ATTACKS}


def resolve_camera_attack(type_name: str) -> type | None:
    """The camera attack class named ``type_name`` (class name as in a LeRobot config), or None."""
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
    return _lerobot_compat.register_image_transform_types(resolve_camera_attack, classes)
