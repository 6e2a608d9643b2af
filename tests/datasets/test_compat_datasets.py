"""The LeRobot seams the datasets package leans on (lerobot_phantom._lerobot_compat, datasets section)."""

from __future__ import annotations

import inspect
import itertools
import os
import subprocess
import sys
from pathlib import Path

import torch

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.datasets import PhantomDataset, camera_attack_params

FRONT, WRIST = "observation.images.front", "observation.images.wrist"


def test_default_features_and_home():
    assert set(compat.default_feature_keys()) == {
        "timestamp",
        "frame_index",
        "episode_index",
        "index",
        "task_index",
    }


def test_lerobot_home_follows_the_environment_variable_lerobot_reads(tmp_path):
    home = tmp_path / "lerobot_home"
    code = "from lerobot_phantom import _lerobot_compat as c; print(c.lerobot_home())"
    env = {**os.environ, "HF_LEROBOT_HOME": str(home)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert Path(out.stdout.strip()) == home


def test_aggregate_datasets_signature():
    from lerobot.datasets.aggregate import aggregate_datasets

    parameters = inspect.signature(aggregate_datasets).parameters
    assert {"repo_ids", "roots", "aggr_repo_id", "aggr_root"} <= set(parameters)


def test_episode_frame_ranges_tile_the_dataset(image_dataset):
    ranges = [
        compat.episode_frame_range(image_dataset.meta, p) for p in range(image_dataset.meta.total_episodes)
    ]
    assert [r[0] for r in ranges] == list(range(len(ranges)))
    assert ranges[0][1] == 0 and ranges[-1][2] == len(image_dataset)
    assert all(a[2] == b[1] for a, b in itertools.pairwise(ranges))
    for episode, start, stop in ranges:
        assert (
            int(image_dataset[start]["episode_index"])
            == episode
            == int(image_dataset[stop - 1]["episode_index"])
        )


def test_lerobot_applies_image_transforms_in_getitem_and_the_mixer_takes_them_over(image_dataset_root):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    def flip_rows(image):
        return image.flip(-2)

    plain = LeRobotDataset("phantom/tiny", root=image_dataset_root)
    augmented = LeRobotDataset("phantom/tiny", root=image_dataset_root, image_transforms=flip_rows)
    assert torch.equal(augmented[4][WRIST], plain[4][WRIST].flip(-2))  # the seam: __getitem__ applies them

    dataset = PhantomDataset(
        augmented, PhantomConfig(rate=1.0, attacks=["em_truncation"], intensity="strong")
    )
    assert augmented.image_transforms is flip_rows and dataset.dataset.image_transforms is None
    item = dataset[4]
    attack = dataset.attacks["em_truncation"]
    (params,) = camera_attack_params(attack, int(item["phantom.seed"]), 1.0, [(32, 32)])
    assert torch.equal(item[FRONT], attack.apply_params(plain[4][FRONT], params).flip(-2))
    assert not torch.equal(item[FRONT], attack.apply_params(plain[4][FRONT].flip(-2), params))
    assert torch.equal(item[WRIST], plain[4][WRIST].flip(-2))
