"""``lerobot-phantom-viz``: the attack gallery (the paper's Figure 3) as one labelled grid.

One row per camera attack, columns clean / weak / medium / strong. The input is an embedded sample tabletop image
(drawn in code, so the package ships no third-party pictures), an image file (``--image``), or a LeRobotDataset
frame (``--dataset.repo_id/--dataset.root --episode --frame --camera``).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
import torch

from lerobot_phantom.transforms.intensity import LEVELS
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS, make_attack

COLUMNS = ("clean", "weak", "medium", "strong")


def sample_image(height: int = 256, width: int = 256) -> torch.Tensor:
    """A deterministic tabletop scene (wall, wooden table, cube, can, bowl, plate) as uint8 (3, H, W)."""
    scale = 4  # draw large, then downsample: cheap anti-aliasing
    h, w = height * scale, width * scale
    rows = np.linspace(0.0, 1.0, h, dtype=np.float32)[:, None, None]
    cols = np.linspace(0.0, 1.0, w, dtype=np.float32)[None, :, None]
    wall = np.array([200, 205, 215], np.float32) * (0.85 + 0.15 * rows)
    table = np.array([150, 105, 65], np.float32) * (0.8 + 0.3 * rows) * (0.95 + 0.05 * np.sin(cols * 60.0))
    horizon = int(0.38 * h)
    img = np.where(np.arange(h)[:, None, None] < horizon, wall, table)
    img = np.ascontiguousarray(np.broadcast_to(img, (h, w, 3)).astype(np.float32))

    def px(x: float, y: float) -> tuple[int, int]:
        return int(x * w), int(y * h)

    def shadow(center: tuple[float, float], axes: tuple[float, float]) -> None:
        overlay = img.copy()
        cv2.ellipse(overlay, px(*center), (int(axes[0] * w), int(axes[1] * h)), 0, 0, 360, (60, 40, 25), -1)
        img[:] = 0.6 * img + 0.4 * overlay

    # plate
    shadow((0.24, 0.80), (0.14, 0.05))
    cv2.ellipse(img, px(0.23, 0.77), (int(0.14 * w), int(0.055 * h)), 0, 0, 360, (235, 230, 220), -1)
    cv2.ellipse(img, px(0.23, 0.77), (int(0.10 * w), int(0.038 * h)), 0, 0, 360, (215, 210, 200), -1)
    # red cube
    shadow((0.45, 0.70), (0.08, 0.03))
    cv2.rectangle(img, px(0.38, 0.55), px(0.50, 0.70), (200, 40, 35), -1)
    cv2.fillConvexPoly(
        img, np.array([px(0.38, 0.55), px(0.42, 0.50), px(0.54, 0.50), px(0.50, 0.55)]), (230, 70, 60)
    )
    cv2.fillConvexPoly(
        img, np.array([px(0.50, 0.55), px(0.54, 0.50), px(0.54, 0.65), px(0.50, 0.70)]), (150, 25, 20)
    )
    # blue can
    shadow((0.70, 0.67), (0.07, 0.025))
    cv2.rectangle(img, px(0.64, 0.42), px(0.76, 0.66), (40, 80, 190), -1)
    cv2.ellipse(img, px(0.70, 0.66), (int(0.06 * w), int(0.02 * h)), 0, 0, 180, (40, 80, 190), -1)
    cv2.ellipse(img, px(0.70, 0.42), (int(0.06 * w), int(0.02 * h)), 0, 0, 360, (170, 180, 200), -1)
    cv2.rectangle(img, px(0.64, 0.50), px(0.76, 0.55), (240, 240, 240), -1)
    # green bowl
    shadow((0.82, 0.86), (0.11, 0.04))
    cv2.ellipse(img, px(0.80, 0.80), (int(0.11 * w), int(0.07 * h)), 0, 0, 180, (40, 140, 60), -1)
    cv2.ellipse(img, px(0.80, 0.80), (int(0.11 * w), int(0.03 * h)), 0, 0, 360, (70, 170, 90), -1)
    cv2.ellipse(img, px(0.80, 0.80), (int(0.09 * w), int(0.022 * h)), 0, 0, 360, (30, 100, 45), -1)

    small = cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA)
    return torch.from_numpy(np.clip(small, 0, 255).round().astype(np.uint8)).permute(2, 0, 1).contiguous()


def load_image(path: str | Path) -> torch.Tensor:
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"--image {path} does not exist")
    bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if bgr is None:
        raise ValueError(f"--image {path} is not an image OpenCV can read (PNG, JPEG, ...)")
    return torch.from_numpy(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)).permute(2, 0, 1).contiguous()


def load_dataset_frame(
    repo_id: str, root: str | None, episode: int, frame: int, camera: str | None
) -> torch.Tensor:
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset(repo_id, root=root, episodes=[episode])
    cameras = dataset.meta.camera_keys
    if not cameras:
        raise ValueError(f"dataset {repo_id} has no camera keys")
    camera = camera or cameras[0]
    if camera not in cameras:
        raise ValueError(f"unknown camera {camera!r}; dataset {repo_id} has {cameras}")
    if not 0 <= frame < len(dataset):
        raise ValueError(f"--frame {frame} out of range: episode {episode} has {len(dataset)} frames")
    image = dataset[frame][camera]
    return (image.clamp(0, 1) * 255).round().to(torch.uint8)


def render_gallery(
    image: torch.Tensor,
    attacks: tuple[str, ...] = CAMERA_ATTACKS,
    seed: int = 0,
    calibration: str | None = None,
) -> np.ndarray:
    """Attack ``image`` (uint8 CHW) at every level; returns the grid as HxWx3 uint8 (rows = attacks)."""
    rows = []
    for row, name in enumerate(attacks):
        cells = [image]
        for col, level in enumerate(COLUMNS[1:]):
            attack = make_attack(name, intensity=level, calibration=calibration)
            params = attack.sample_params(
                1,
                image.shape[-2],
                image.shape[-1],
                intensity=torch.tensor([LEVELS[level]]),
                generator=torch.Generator().manual_seed(seed * 1000 + row * 10 + col),
            )
            cells.append(attack.apply_params(image, params))
        rows.append(torch.stack(cells))
    return torch.stack(rows).permute(0, 1, 3, 4, 2).numpy()


def save_gallery(grid: np.ndarray, attacks: tuple[str, ...], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n_rows, n_cols = grid.shape[:2]
    fig, axes = plt.subplots(n_rows, n_cols, figsize=(2.2 * n_cols + 1.4, 2.2 * n_rows), squeeze=False)
    for r in range(n_rows):
        for c in range(n_cols):
            ax = axes[r][c]
            ax.imshow(grid[r, c])
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(COLUMNS[c], fontsize=12)
            if c == 0:
                ax.set_ylabel(attacks[r].replace("_", " "), fontsize=11)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=100)
    plt.close(fig)


@dataclass
class VizDatasetConfig:
    repo_id: str | None = None
    root: str | None = None


@dataclass
class VizConfig:
    out: str = "attacks.png"
    # An image file to attack instead of the embedded sample.
    image: str | None = None
    # A LeRobotDataset frame to attack instead (offline: give --dataset.root).
    dataset: VizDatasetConfig = field(default_factory=VizDatasetConfig)
    episode: int = 0
    frame: int = 0
    camera: str | None = None
    # Size of the embedded sample image.
    size: int = 256
    seed: int = 0
    calibration: str | None = None


def viz(cfg: VizConfig) -> Path:
    if cfg.image and cfg.dataset.repo_id:
        raise ValueError("give either --image or --dataset.repo_id, not both")
    if cfg.image:
        image = load_image(cfg.image)
    elif cfg.dataset.repo_id:
        image = load_dataset_frame(cfg.dataset.repo_id, cfg.dataset.root, cfg.episode, cfg.frame, cfg.camera)
    else:
        image = sample_image(cfg.size, cfg.size)
    out = Path(cfg.out)
    save_gallery(render_gallery(image, seed=cfg.seed, calibration=cfg.calibration), CAMERA_ATTACKS, out)
    logging.info("wrote %s", out)
    return out


def main() -> None:
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    import draccus

    logging.basicConfig(level=logging.INFO, format="%(message)s")
    cfg = draccus.parse(config_class=VizConfig)
    print(viz(cfg))


if __name__ == "__main__":
    main()
