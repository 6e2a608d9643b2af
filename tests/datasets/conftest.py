"""Fixtures of the datasets tests: a small image dataset built once per session."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from lerobot_phantom.datasets.synthetic import build_synthetic_dataset

os.environ.setdefault("HF_HUB_OFFLINE", "1")


@pytest.fixture(scope="session")
def image_dataset_root(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("src") / "tiny_images"
    build_synthetic_dataset(root, "phantom/tiny")
    return root


@pytest.fixture
def image_dataset(image_dataset_root):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    return LeRobotDataset("phantom/tiny", root=image_dataset_root)
