"""The microscopic study config shared by the study tests (a module of its own: `conftest` names collide)."""

import os

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from pathlib import Path

from lerobot_phantom.study.config import (
    CleanTrainSettings,
    CollectSettings,
    LoRASettings,
    SelectSettings,
    StudyConfig,
    SweepSettings,
    VLMSettings,
)

REPO = Path(__file__).resolve().parents[2]
TINY_CONFIG = str(REPO / "configs" / "tiny_smolvla_cpu.json")


def micro_config(output_dir, **changes) -> StudyConfig:
    """2 demos, tiny VLM, 2 training steps per run, 2 conditions (clean + strong laser blinding) x 2 episodes;
    both clean checkpoints (steps 1 and 2) validated on 2 episodes."""
    settings = {
        "output_dir": str(output_dir),
        "collect": CollectSettings(episodes=2, image_size=32),
        "vlm": VLMSettings(size="tiny"),
        "train": CleanTrainSettings(config_path=TINY_CONFIG, steps=2, batch_size=4, save_freq=1),
        "select": SelectSettings(n_episodes=2, batch_size=2),
        "lora": LoRASettings(steps=2, batch_size=4, lora_rank=4),
        "sweep": SweepSettings(
            n_episodes=2,
            batch_size=2,
            attacks=("laser_blinding",),
            intensities=("strong",),
            extra_args=("--env.episode_length=8",),
        ),
        "in_process": True,
        "verbose": False,
    }
    settings.update(changes)
    return StudyConfig(**settings)
