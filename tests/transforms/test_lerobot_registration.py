import json
import os

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import pytest
import torch

from lerobot_phantom import _lerobot_compat
from lerobot_phantom.transforms.lerobot_registration import (
    camera_attack_class_names,
    register_image_transforms,
    resolve_camera_attack,
)
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS

transforms_module = pytest.importorskip("lerobot.datasets.transforms")
ImageTransformConfig = transforms_module.ImageTransformConfig
ImageTransformsConfig = transforms_module.ImageTransformsConfig
ImageTransforms = transforms_module.ImageTransforms


@pytest.fixture
def registered():
    register_image_transforms()
    yield
    register_image_transforms()  # leave the plugin registered, as lerobot_phantom.register() does


def _config(type_name, **kwargs):
    return ImageTransformsConfig(
        enable=True, max_num_transforms=1, tfs={"attack": ImageTransformConfig(type=type_name, kwargs=kwargs)}
    )


def test_lerobot_seam_is_where_we_expect():
    # LeRobot 0.4.4: ImageTransforms builds each entry through this module-level factory.
    assert _lerobot_compat.lerobot_version() == _lerobot_compat.LEROBOT_VERSION
    original = _lerobot_compat.original_make_transform_from_config()
    assert original.__module__ == "lerobot.datasets.transforms"
    assert original.__name__ == "make_transform_from_config"


def test_unregistered_lerobot_rejects_the_attack_then_accepts_it_after_registration():
    _lerobot_compat.unregister_image_transform_types()
    try:
        with pytest.raises(ValueError, match="not valid"):
            ImageTransforms(_config("LaserBlinding", intensity="medium"))
    finally:
        register_image_transforms()
    transforms = ImageTransforms(_config("LaserBlinding", intensity="medium"))
    assert type(transforms.transforms["attack"]).__name__ == "LaserBlinding"


def test_registration_is_idempotent_and_keeps_the_original(registered):
    first = transforms_module.make_transform_from_config
    assert register_image_transforms() == "wrapped"
    assert transforms_module.make_transform_from_config is first
    assert first.__phantom_original__ is _lerobot_compat.original_make_transform_from_config()
    assert not hasattr(first.__phantom_original__, "__phantom_original__")  # never a wrapper of a wrapper


def test_image_transforms_apply_the_attack(registered):
    transforms = ImageTransforms(_config("LaserBlinding", intensity="medium", seed=0))
    image = torch.rand(3, 24, 32, generator=torch.Generator().manual_seed(0))
    out = transforms(image)
    assert out.shape == image.shape and out.dtype == image.dtype
    assert float((out - image).abs().mean()) > 0.05


def test_torchvision_and_unknown_types_still_go_through_lerobot(registered):
    assert type(
        ImageTransforms(_config("ColorJitter", brightness=(0.8, 1.2))).transforms["attack"]
    ).__name__ == ("ColorJitter")
    with pytest.raises(ValueError, match=r"torchvision\.transforms\.v2 or 'SharpnessJitter'"):
        ImageTransforms(_config("NoSuchTransform"))
    with pytest.raises(ValueError, match="not valid"):
        ImageTransforms(_config("VoiceDoS"))  # instruction attacks are not image transforms


def test_every_camera_attack_has_a_class_name():
    names = camera_attack_class_names()
    assert sorted(names.values()) == sorted(CAMERA_ATTACKS)
    assert resolve_camera_attack("VoiceSpoofing") is None
    assert resolve_camera_attack("ColorJitter") is None
    assert resolve_camera_attack("LightProjection").name == "light_projection"
    assert resolve_camera_attack("PhantomMix").name == "phantom_mix"


def test_dataset_config_from_json_goes_through_make_dataset(registered, tmp_path):
    import draccus
    from lerobot.configs.default import DatasetConfig
    from lerobot.configs.train import TrainPipelineConfig
    from lerobot.datasets.factory import make_dataset
    from lerobot.datasets.lerobot_dataset import LeRobotDataset
    from lerobot.policies.act.configuration_act import ACTConfig

    from lerobot_phantom.datasets.synthetic import build_synthetic_dataset

    root = tmp_path / "tiny"
    build_synthetic_dataset(root, "phantom/tiny", episode_lengths=(3,), cameras=("observation.image",))
    text = json.dumps(
        {
            "repo_id": "phantom/tiny",
            "root": str(root),
            "use_imagenet_stats": False,
            "image_transforms": {
                "enable": True,
                "max_num_transforms": 1,
                "tfs": {"laser": {"weight": 1.0, "type": "LaserBlinding", "kwargs": {"intensity": "strong"}}},
            },
        }
    )
    dataset_cfg = draccus.decode(DatasetConfig, json.loads(text))
    assert dataset_cfg.image_transforms.tfs["laser"].type == "LaserBlinding"
    cfg = TrainPipelineConfig(
        dataset=dataset_cfg, policy=ACTConfig(push_to_hub=False, chunk_size=1, n_action_steps=1)
    )
    dataset = make_dataset(cfg)
    raw = LeRobotDataset("phantom/tiny", root=root)
    attacked, clean = dataset[1]["observation.image"], raw[1]["observation.image"]
    assert attacked.shape == clean.shape
    assert float((attacked - clean).abs().mean()) > 0.1  # strong laser: alpha 0.9


def test_newer_lerobot_custom_transforms_table_is_used_when_present(registered, monkeypatch):
    table = {"SharpnessJitter": transforms_module.SharpnessJitter}
    monkeypatch.setattr(transforms_module, "_CUSTOM_TRANSFORMS", table, raising=False)
    factory_before = transforms_module.make_transform_from_config
    assert register_image_transforms() == "table"
    assert set(table) == {"SharpnessJitter", "PhantomMix", *camera_attack_class_names()}
    assert table["UltrasoundBlur"].name == "ultrasound_blur" and table["PhantomMix"].name == "phantom_mix"
    assert transforms_module.make_transform_from_config is factory_before  # the table, not the wrapper
