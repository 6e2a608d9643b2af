"""The one place where lerobot-phantom touches LeRobot internals (pinned: lerobot==0.4.4).

Everything here leans on names that are not LeRobot's public API. tests/test_lerobot_compat.py checks each seam,
so that a LeRobot upgrade fails loudly here instead of quietly elsewhere. Sections: version pin, transforms,
datasets, training, environments, evaluation.
"""

from __future__ import annotations

from importlib.metadata import version

LEROBOT_VERSION = "0.4.4"


def lerobot_version() -> str:
    return version("lerobot")
