"""Shared, session-scoped artefacts of the train tests: a tiny dataset, a tiny VLM directory, one clean run."""

import os

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from pathlib import Path

import pytest
from train_testkit import FRAMES, smolvla_args


@pytest.fixture(scope="session")
def tiny_dataset_root(tmp_path_factory) -> Path:
    from lerobot_phantom.datasets.synthetic import build_synthetic_dataset

    root = tmp_path_factory.mktemp("data") / "tiny"
    build_synthetic_dataset(
        root, "phantom/tiny", episode_lengths=(FRAMES // 2,) * 2, cameras=("observation.images.front",)
    )
    return root


@pytest.fixture(scope="session")
def tiny_vlm(tmp_path_factory) -> Path:
    from lerobot_phantom.datasets.synthetic import TASKS
    from lerobot_phantom.train.make_vlm import make_vlm

    return make_vlm(tmp_path_factory.mktemp("vlm") / "tiny_vlm", "tiny", tasks=TASKS)


@pytest.fixture(scope="session")
def clean_smolvla_run(tmp_path_factory, tiny_dataset_root, tiny_vlm) -> Path:
    """Stage one of the recipe: a clean (rate 0) SmolVLA run; returns its output dir."""
    from lerobot_phantom.train.train import main

    out = tmp_path_factory.mktemp("runs") / "clean"
    main(smolvla_args(tiny_dataset_root, tiny_vlm, out, "--steps=2", "--save_freq=2", "--phantom.rate=0"))
    return out
