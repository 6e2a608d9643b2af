import json
from pathlib import Path

from lerobot_phantom.train import SMOLVLA_VISION_LORA_TARGETS

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


def test_shipped_smolvla_config_uses_the_package_lora_targets():
    config = json.loads((CONFIGS / "smolvla_lora_phantom.json").read_text())
    assert config["peft"]["target_modules"] == SMOLVLA_VISION_LORA_TARGETS
