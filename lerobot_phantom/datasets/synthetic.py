"""A small synthetic LeRobotDataset v3 (2 cameras, state, action, 2 tasks) for tests and benchmarks.

Frames are gradients plus noise, so that every attack visibly changes them; content is a pure function of
``seed``. Not a stand-in for real data: use the collection CLI or a recorded dataset for training.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

CAMERAS = ("observation.images.front", "observation.images.wrist")
TASKS = ("put the red block in the bowl", "stack the green block on the blue block")


def synthetic_features(
    use_videos: bool, size: int = 32, cameras: tuple[str, ...] = CAMERAS
) -> dict[str, dict[str, Any]]:
    features: dict[str, dict[str, Any]] = {
        key: {
            "dtype": "video" if use_videos else "image",
            "shape": (size, size, 3),
            "names": ["height", "width", "channels"],
        }
        for key in cameras
    }
    features["observation.state"] = {"dtype": "float32", "shape": (4,), "names": [f"q{i}" for i in range(4)]}
    features["action"] = {"dtype": "float32", "shape": (3,), "names": ["x", "y", "z"]}
    return features


def build_synthetic_dataset(
    root: str | Path,
    repo_id: str = "phantom/synthetic",
    *,
    episode_lengths: tuple[int, ...] = (12, 9, 15),
    use_videos: bool = False,
    size: int = 32,
    fps: int = 10,
    seed: int = 0,
    cameras: tuple[str, ...] = CAMERAS,
) -> Any:
    """Write the dataset under ``root`` (which must not exist) and return it reopened as a ``LeRobotDataset``.

    ``cameras`` are full feature keys (default: front and wrist)."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    rng = np.random.default_rng(seed)
    dataset = LeRobotDataset.create(
        repo_id=repo_id,
        fps=fps,
        features=synthetic_features(use_videos, size, cameras),
        root=root,
        use_videos=use_videos,
    )
    yy, xx = np.mgrid[0:size, 0:size]
    for episode, length in enumerate(episode_lengths):
        for frame in range(length):
            sample: dict[str, Any] = {"task": TASKS[episode % len(TASKS)]}
            for k, key in enumerate(cameras):
                base = np.stack([xx * 7 + frame, yy * 5 + 40 * k, (xx + yy) * 3 + 13 * episode], axis=-1)
                noise = rng.integers(0, 40, size=(size, size, 3))
                sample[key] = ((base + noise) % 256).astype(np.uint8)
            sample["observation.state"] = rng.normal(size=4).astype(np.float32)
            sample["action"] = rng.normal(size=3).astype(np.float32)
            dataset.add_frame(sample)
        dataset.save_episode()
    dataset.finalize()
    return LeRobotDataset(repo_id, root=root)
