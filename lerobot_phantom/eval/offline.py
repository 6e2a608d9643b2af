"""Offline mode of ``lerobot-phantom-eval`` (``--dataset.*`` instead of ``--env.*``): no simulator, recorded frames.

For real-robot data there is no success predicate, so the measure is how far the policy's action moves when its
input is attacked: for each frame, the same policy (same RNG state, fresh action queue) acts on the clean frame and
on the attacked frame, and the distance between the two actions is recorded. Distances are reported raw (L2, in
action units) and normalised by the dataset's per-dimension action std (RMS of z-scores), next to the clean
policy's own distance from the recorded action as a yardstick.

    lerobot-phantom-eval --policy.path=CKPT --dataset.repo_id=local/real --dataset.root=DIR \\
        --phantom.attacks='[laser_blinding,voice_dos]' --phantom.offline_frames=256 --eval.batch_size=16
"""

import statistics
import time
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from typing import Any

import numpy as np
import torch
from tqdm import tqdm

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.eval.config import PhantomEvalConfig
from lerobot_phantom.eval.loading import (
    identity_processors,
    policy_metadata,
    ready_policy,
    versions,
    with_step,
)
from lerobot_phantom.eval.results import EVAL_FORMAT, write_eval
from lerobot_phantom.eval.rollout import AttackStep, Condition, attack_steps
from lerobot_phantom.transforms.base import derive_seed


def frame_indices(n_frames: int, wanted: int) -> list[int]:
    """At most ``wanted`` frame indices spread evenly over the dataset (first and last included)."""
    if n_frames < 1:
        raise ValueError("the dataset has no frames")
    return sorted({int(i) for i in np.linspace(0, n_frames - 1, min(wanted, n_frames)).round()})


def act(policy, preprocessor, postprocessor, batch: dict[str, Any], seed: int) -> torch.Tensor:
    """The policy's first action for each frame of ``batch``, from an empty action queue and a fixed RNG state."""
    compat.eval_seed_everything(seed)
    policy.reset()
    with torch.inference_mode():
        action = policy.select_action(preprocessor(dict(batch)))
    return postprocessor(action).to("cpu", torch.float32).reshape(len(batch["index"]), -1)


def deviation_stats(distances: list[float], normalised: list[float]) -> dict[str, float]:
    return {
        "mean_l2": statistics.fmean(distances),
        "median_l2": statistics.median(distances),
        "max_l2": max(distances),
        "mean_normalized": statistics.fmean(normalised),
    }


@dataclass
class Deviations:
    """Per-frame distances between attacked and clean actions, per condition (raw L2 and std-normalised)."""

    conditions: list[Condition]
    distances: list[list[float]] = field(default_factory=list)
    normalised: list[list[float]] = field(default_factory=list)
    clean_vs_recorded: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.distances = [[] for _ in self.conditions]
        self.normalised = [[] for _ in self.conditions]

    def add(self, k: int, diff: torch.Tensor, action_std: torch.Tensor) -> None:
        self.distances[k] += diff.norm(dim=1).tolist()
        self.normalised[k] += (diff / action_std).pow(2).mean(dim=1).sqrt().tolist()

    def rows(self, frames: int) -> list[dict[str, Any]]:
        return [
            {
                "condition": condition.key,
                "attack": condition.attack,
                "intensity": condition.intensity,
                "intensity_value": condition.intensity_value,
                "frames": frames,
                **deviation_stats(self.distances[k], self.normalised[k]),
                "per_frame_l2": [round(d, 6) for d in self.distances[k]],
            }
            for k, condition in enumerate(self.conditions)
        ]


def load_dataset(cfg: PhantomEvalConfig):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    return LeRobotDataset(
        cfg.dataset.repo_id,
        root=cfg.dataset.root,
        episodes=cfg.dataset.episodes,
        revision=cfg.dataset.revision,
        video_backend=cfg.dataset.video_backend,
    )


def measure(cfg: PhantomEvalConfig, dataset, indices: list[int], steps: list[AttackStep], policy, processors):
    """Clean and attacked first actions on every chosen frame, batch by batch (same RNG state for both)."""
    from torch.utils.data import Subset, default_collate

    preprocessor, postprocessor = processors
    identity, _ = identity_processors()
    attackers = [with_step(identity, step) for step in steps]
    std = dataset.meta.stats["action"]["std"]
    action_std = torch.as_tensor(np.asarray(std), dtype=torch.float32).reshape(-1).clamp(min=1e-6)
    frames = Subset(dataset, indices)
    deviations = Deviations([step.condition for step in steps])
    progress = tqdm(total=len(indices) * len(steps), desc="conditions x frames")
    try:
        for start in range(0, len(indices), cfg.eval.batch_size):
            stop = min(start + cfg.eval.batch_size, len(indices))
            batch = default_collate([frames[i] for i in range(start, stop)])
            seed = derive_seed(cfg.seed or 0, start) % 2**32
            clean = act(policy, preprocessor, postprocessor, batch, seed)
            deviations.clean_vs_recorded += (
                (clean - batch["action"].reshape(clean.shape)).norm(dim=1).tolist()
            )
            for k, (step, attacker) in enumerate(zip(steps, attackers, strict=True)):
                # Each frame is its own "episode": its attack parameters are seeded by its dataset index.
                step.arm(batch["index"].tolist())
                attacked = act(policy, preprocessor, postprocessor, attacker(dict(batch)), seed)
                deviations.add(k, attacked - clean, action_std)
                progress.update(len(clean))
    finally:
        progress.close()
    return deviations


def evaluate_offline(
    cfg: PhantomEvalConfig, policy=None, preprocessor=None, postprocessor=None
) -> dict[str, Any]:
    """Action deviation clean vs attacked per condition over dataset frames; writes and returns eval.json."""
    if cfg.phantom.onset != 0 or cfg.phantom.duration is not None:
        raise ValueError(
            "--phantom.onset/--phantom.duration need rollouts (--env.*); offline frames are single steps"
        )
    started = time.time()
    dataset = load_dataset(cfg)
    # The clean frame is every condition's reference, so the clean control is not a condition here.
    steps = attack_steps(cfg.phantom)[1:]
    policy, preprocessor, postprocessor = ready_policy(
        cfg, policy, preprocessor, postprocessor, ds_meta=dataset.meta
    )
    indices = frame_indices(len(dataset), cfg.phantom.offline_frames)
    deviations = measure(cfg, dataset, indices, steps, policy, (preprocessor, postprocessor))
    report = {
        "format": EVAL_FORMAT,
        "mode": "offline",
        "metadata": {
            "created": datetime.fromtimestamp(started, UTC).isoformat(timespec="seconds"),
            "duration_s": round(time.time() - started, 3),
            "policy": policy_metadata(cfg, policy),
            "dataset": {
                "repo_id": cfg.dataset.repo_id,
                "root": None if cfg.dataset.root is None else str(cfg.dataset.root),
            },
            "frame_indices": indices,
            "seed": cfg.seed,
            "clean_vs_recorded_l2": statistics.fmean(deviations.clean_vs_recorded),
            "conditions": [step.condition.key for step in steps],
            "phantom": asdict(cfg.phantom),
            "calibrated_attacks": sorted({step.condition.attack for step in steps if step.calibrated}),
            "versions": versions(),
        },
        "results": deviations.rows(len(indices)),
    }
    write_eval(cfg.output_dir, report)
    return report
