"""The device-side attack step: same pixels and tasks as the dataloader path; never saved with a checkpoint."""

import json

import pytest
import torch
from torch.utils.data import default_collate

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.datasets import PhantomDataset
from lerobot_phantom.train.device_step import (
    ATTACK_STEP_NAME,
    PhantomAttackProcessorStep,
    TrainingPreprocessor,
)
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS

CAMERAS = ("observation.images.front", "observation.images.wrist")


@pytest.fixture(scope="module")
def two_camera_dataset(tmp_path_factory):
    """Two cameras; the front one as a 2-frame stack (delta_timestamps), the wrist one as a single frame."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_phantom.datasets.synthetic import build_synthetic_dataset

    root = tmp_path_factory.mktemp("two_cams") / "ds"
    build_synthetic_dataset(root, "phantom/tiny", episode_lengths=(16,), size=24)
    return LeRobotDataset("phantom/tiny", root=root, delta_timestamps={CAMERAS[0]: [-0.1, 0.0]})


def collated(dataset, indices):
    return default_collate([dataset[i] for i in indices])


def identity_pipeline():
    from lerobot.processor import PolicyProcessorPipeline

    return PolicyProcessorPipeline(steps=[], name="policy_preprocessor")


@pytest.mark.parametrize("cameras", [["all"], ["random"], [CAMERAS[1], CAMERAS[0]]])
def test_device_step_reproduces_the_dataloader_path(two_camera_dataset, cameras):
    config = PhantomConfig(
        rate=0.9,
        attacks=[*CAMERA_ATTACKS, "voice_dos"],
        cameras=cameras,
        instruction_attacks=["voice_spoofing"],
        instruction_rate=0.5,
        seed=3,
    )
    on_cpu_workers = PhantomDataset(two_camera_dataset, config, apply=True)
    labels_only = PhantomDataset(two_camera_dataset, config, apply=False)
    step = PhantomAttackProcessorStep(phantom=config, camera_keys=list(labels_only.camera_keys), device="cpu")
    preprocessor = TrainingPreprocessor(identity_pipeline(), step)
    indices = list(range(len(labels_only)))
    expected = collated(on_cpu_workers, indices)
    got = preprocessor(collated(labels_only, indices))

    assert expected[CAMERAS[0]].ndim == 5  # the frame stack shares one parameter set per sample
    attacked = expected["phantom.attack"] >= 0
    assert attacked.sum() >= len(indices) // 2
    clean_input = collated(two_camera_dataset, indices)
    for key in CAMERAS:
        torch.testing.assert_close(got[key], expected[key], atol=1e-5, rtol=0)
        changed = (got[key] - clean_input[key]).flatten(1).abs().amax(1) > 0
        assert changed.any() and not changed[~attacked].any()
    assert got["task"] == expected["task"]
    assert got["task"] != clean_input["task"]
    for label in ("phantom.attack", "phantom.seed", "phantom.camera"):
        assert torch.equal(got[label], expected[label])  # labels kept for the per-attack loss


def test_training_preprocessor_saves_only_the_clean_pipeline(tmp_path, two_camera_dataset):
    config = PhantomConfig(rate=1.0, attacks=["laser_blinding"], cameras=["all"])
    labels_only = PhantomDataset(two_camera_dataset, config, apply=False)
    step = PhantomAttackProcessorStep(phantom=config, camera_keys=list(labels_only.camera_keys))
    pipeline = identity_pipeline()
    preprocessor = TrainingPreprocessor(pipeline, step)

    preprocessor.save_pretrained(tmp_path)
    saved = json.loads((tmp_path / "policy_preprocessor.json").read_text())
    assert ATTACK_STEP_NAME not in json.dumps(saved)
    assert preprocessor.steps == pipeline.steps == []

    # A batch without the mixer's labels (an eval rollout) goes through the clean pipeline untouched.
    clean = collated(two_camera_dataset, [0, 1])
    out = preprocessor(dict(clean))
    torch.testing.assert_close(out[CAMERAS[1]], clean[CAMERAS[1]])
    # The step itself refuses to guess when called without labels.
    with pytest.raises(KeyError, match=r"phantom\.attack"):
        step({"observation": {CAMERAS[1]: clean[CAMERAS[1]]}, "complementary_data": {}})


def test_attack_step_is_registered_and_round_trips_its_config():
    from lerobot.processor import ProcessorStepRegistry

    assert ProcessorStepRegistry.get(ATTACK_STEP_NAME) is PhantomAttackProcessorStep
    step = PhantomAttackProcessorStep(
        phantom=PhantomConfig(rate=0.5, attacks=["em_truncation"], seed=9), camera_keys=[CAMERAS[0]]
    )
    rebuilt = PhantomAttackProcessorStep(**json.loads(json.dumps(step.get_config())))
    assert rebuilt.phantom == step.phantom and rebuilt.camera_keys == step.camera_keys
