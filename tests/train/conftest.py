"""Shared, session-scoped artefacts of the train tests: a tiny dataset, a tiny VLM directory, one clean run."""

import os

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CONFIGS = REPO / "configs"
FRAMES = 24  # 2 episodes x 12 frames


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


def dataset_args(root: Path) -> list[str]:
    return ["--dataset.repo_id=phantom/tiny", f"--dataset.root={root}"]


def smolvla_args(root: Path, vlm: Path, out: Path, *extra: str) -> list[str]:
    """The tiny CPU config (configs/tiny_smolvla_cpu.json) pointed at the test's dataset, VLM and output dir."""
    return [
        f"--config_path={CONFIGS / 'tiny_smolvla_cpu.json'}",
        *dataset_args(root),
        f"--policy.vlm_model_name={vlm}",
        f"--output_dir={out}",
        *extra,
    ]


@pytest.fixture(scope="session")
def clean_smolvla_run(tmp_path_factory, tiny_dataset_root, tiny_vlm) -> Path:
    """Stage one of the recipe: a clean (rate 0) SmolVLA run; returns its output dir."""
    from lerobot_phantom.train.train import main

    out = tmp_path_factory.mktemp("runs") / "clean"
    main(smolvla_args(tiny_dataset_root, tiny_vlm, out, "--steps=2", "--save_freq=2", "--phantom.rate=0"))
    return out
