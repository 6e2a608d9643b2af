"""Physical sensor attacks as torchvision v2 transforms (camera) and string transforms (instruction)."""

from lerobot_phantom.transforms.intensity import LEVELS, RANDOM_RANGE, parse_intensity
from lerobot_phantom.transforms.registry import (
    ATTACK_IDS,
    ATTACK_NAMES,
    CAMERA_ATTACKS,
    CLEAN_ID,
    INSTRUCTION_ATTACKS,
    get_attack_class,
    make_attack,
)

__all__ = [
    "ATTACK_IDS",
    "ATTACK_NAMES",
    "CAMERA_ATTACKS",
    "CLEAN_ID",
    "INSTRUCTION_ATTACKS",
    "LEVELS",
    "RANDOM_RANGE",
    "get_attack_class",
    "make_attack",
    "parse_intensity",
]
