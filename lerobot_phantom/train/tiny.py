"""A tiny LeRobotDataset (v3) built from seeded noise: for tests, benchmarks and offline smoke runs.

It is not a task anyone can learn; it only has the shapes, features and metadata of a real single-arm dataset.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

TINY_TASKS = ("pick up the red cube", "place the cube in the bowl")


def make_tiny_dataset(
    root: str | Path,
    *,
    repo_id: str = "phantom/tiny",
    episodes: int = 2,
    frames_per_episode: int = 12,
    image_size: int = 32,
    cameras: tuple[str, ...] = ("front",),
    state_dim: int = 4,
    fps: int = 10,
    seed: int = 0,
):
    """Write and return a LeRobotDataset at ``root`` (must not exist), images stored as PNG (no video codec)."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    features = {
        f"observation.images.{cam}": {
            "dtype": "image",
            "shape": (image_size, image_size, 3),
            "names": ["height", "width", "channels"],
        }
        for cam in cameras
    }
    features["observation.state"] = {"dtype": "float32", "shape": (state_dim,), "names": None}
    features["action"] = {"dtype": "float32", "shape": (state_dim,), "names": None}
    dataset = LeRobotDataset.create(repo_id, fps=fps, features=features, root=root, use_videos=False)
    rng = np.random.default_rng(seed)
    for episode in range(episodes):
        task = TINY_TASKS[episode % len(TINY_TASKS)]
        for _ in range(frames_per_episode):
            frame = {
                f"observation.images.{cam}": rng.integers(0, 256, (image_size, image_size, 3), dtype=np.uint8)
                for cam in cameras
            }
            frame["observation.state"] = rng.standard_normal(state_dim).astype(np.float32)
            frame["action"] = rng.standard_normal(state_dim).astype(np.float32)
            frame["task"] = task
            dataset.add_frame(frame)
        dataset.save_episode()
    dataset.finalize()
    return LeRobotDataset(repo_id, root=root)
