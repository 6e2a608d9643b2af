"""Rollouts under attack: LeRobot's own ``rollout()`` with one extra env-processor step that plays the attacker.

The seam: LeRobot's eval loop turns raw env observations into the policy's batch as
``preprocess_observation -> add_envs_task -> env_preprocessor -> preprocessor -> policy.select_action``.
``AttackStep`` is appended to the *env* preprocessor, so it sees exactly the images the policy will see (after any
env-specific flips such as LIBERO's) as float (B, C, H, W) tensors on the CPU, and the ``task`` strings, before the
policy's own normalisation/tokenisation. Nothing else in LeRobot's loop changes, so clean numbers equal stock
``lerobot-eval``'s for the same seeds.

Per-episode parameters: each env of a batch draws its attack parameters once per episode from a generator seeded by
``(phantom.seed, attack, intensity, episode seed, camera)``, so an episode's attack does not depend on the batch size
or on which other conditions ran, and it stays fixed over the episode (a physical attacker's rig does not move).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from lerobot.processor import ProcessorStep, TransitionKey
from lerobot.utils.constants import OBS_IMAGE as OBSERVATION_IMAGE_PREFIX

from lerobot_phantom.eval.config import EvalPhantomConfig
from lerobot_phantom.eval.results import CLEAN
from lerobot_phantom.transforms.base import derive_seed
from lerobot_phantom.transforms.calibrated import calibrated_options
from lerobot_phantom.transforms.intensity import parse_intensity
from lerobot_phantom.transforms.registry import ATTACK_NAMES, is_camera_attack, make_attack


@dataclass(frozen=True)
class Condition:
    """One evaluated condition: the clean control, or one attack at one intensity."""

    attack: str
    intensity: str | None = None

    @property
    def key(self) -> str:
        return self.attack if self.intensity is None else f"{self.attack}@{self.intensity}"

    @property
    def sampled_intensity(self) -> str:
        """What the attack samples at: the condition's level; full strength for an all-or-nothing condition."""
        return "strong" if self.intensity is None else self.intensity

    @property
    def intensity_value(self) -> float:
        """Intensity on the [0, 1] scale (0 for clean); a range reports its midpoint."""
        if self.attack == CLEAN:
            return 0.0
        if self.intensity is None:
            return 1.0
        low, high = parse_intensity(self.intensity)
        return (low + high) / 2.0

    @property
    def is_camera(self) -> bool:
        return self.attack != CLEAN and is_camera_attack(self.attack)


def build_conditions(phantom: EvalPhantomConfig) -> list[Condition]:
    """The clean control first, then every attack (registry order) at every intensity (given order).

    Instruction attacks in the paper's mode act in full at any intensity, so they get one condition each (intensity
    ``None``, key = the attack's name), as the single VD/VS rows of the paper's Table 3.
    """
    conditions = [Condition(CLEAN)]
    for name in (n for n in ATTACK_NAMES if n in phantom.attacks):
        if not is_camera_attack(name) and phantom.instruction_mode == "paper":
            conditions.append(Condition(name))
        else:
            conditions.extend(Condition(name, level) for level in phantom.intensities)
    return conditions


def image_keys(observation: dict[str, Any]) -> list[str]:
    """Camera keys of a LeRobot observation batch, in the env's own order (LeRobot keeps the ``pixels`` order)."""
    return [
        key
        for key, value in observation.items()
        if key.startswith(OBSERVATION_IMAGE_PREFIX) and isinstance(value, torch.Tensor) and value.ndim == 4
    ]


def resolve_cameras(requested: Sequence[str], available: Sequence[str]) -> list[str] | None:
    """Camera keys to attack; ``None`` means 'one at random per episode'. Accepts full keys or short names."""
    if not available:
        raise ValueError(
            "camera attacks need image observations, but the env's observation has no image keys"
        )
    if list(requested) == ["first"]:
        return [available[0]]
    if list(requested) == ["all"]:
        return list(available)
    if list(requested) == ["random"]:
        return None
    resolved = []
    for name in requested:
        matches = [k for k in available if k == name or k.rsplit(".", 1)[-1] == name]
        if len(matches) != 1:
            raise ValueError(
                f"--phantom.cameras: {name!r} is not a camera of this env; available: {list(available)} "
                "(or 'first', 'all', 'random')"
            )
        resolved.append(matches[0])
    return resolved


def concat_params(per_episode: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Stack single-episode parameter dicts (leading dim 1 for tensors, length-1 lists) into one batch."""
    out: dict[str, Any] = {}
    for name in per_episode[0]:
        values = [p[name] for p in per_episode]
        if isinstance(values[0], torch.Tensor):
            out[name] = torch.cat(values, dim=0)
        elif isinstance(values[0], list | tuple):
            out[name] = [item for v in values for item in v]
        else:
            raise TypeError(f"cannot batch attack parameter {name!r} of type {type(values[0]).__name__}")
    return out


def scalar_params(params: dict[str, Any], index: int) -> dict[str, float]:
    """The scalar parameters of episode ``index`` (what eval.json records about each attack instance)."""
    out = {}
    for name, value in params.items():
        if isinstance(value, torch.Tensor) and value.ndim >= 1 and value[index].numel() == 1:
            out[name] = round(float(value[index].item()), 6)
    return out


def frames_to_video_frames(observation: dict[str, Any], keys: Sequence[str], count: int) -> np.ndarray:
    """(count, H, W_total, 3) uint8 frames: the policy's camera images side by side."""
    images = [observation[k][:count] for k in keys]
    height = max(img.shape[-2] for img in images)
    padded = [torch.nn.functional.pad(img, (0, 0, 0, height - img.shape[-2])) for img in images]
    row = torch.cat(padded, dim=-1)
    if row.shape[1] == 1:
        row = row.expand(-1, 3, -1, -1)
    return (row[:, :3].clamp(0, 1) * 255).round().to(torch.uint8).permute(0, 2, 3, 1).numpy()


def attack_steps(phantom: EvalPhantomConfig) -> list[AttackStep]:
    """One attacker per condition (clean first), all built now so that a bad name or calibration fails before any
    rollout; ``--phantom.calibration`` gives its measured physics to the attacks it calibrates."""
    options = calibrated_options(phantom.attacks, phantom.calibration)
    return [
        AttackStep(condition, phantom, options.get(condition.attack))
        for condition in build_conditions(phantom)
    ]


class AttackStep(ProcessorStep):
    """The attacker, as the last step of the env preprocessor. ``arm()`` before each batch of episodes."""

    def __init__(
        self,
        condition: Condition,
        phantom: EvalPhantomConfig,
        calibrated_options: dict[str, Any] | None = None,
    ) -> None:
        """``calibrated_options``: the attack's measured physics (``attack_steps`` reads them once for all steps)."""
        self.condition = condition
        self.phantom = phantom
        self.calibrated = calibrated_options is not None
        attack = None
        if condition.attack != CLEAN:
            extra = {} if condition.is_camera else {"mode": phantom.instruction_mode}
            attack = make_attack(
                condition.attack,
                intensity=condition.sampled_intensity,
                **(calibrated_options or {}),
                **extra,
            )
        self.attack = attack
        self.seeds: list[int] = []
        self.step = 0
        self.record = 0
        self.frames: list[np.ndarray] = []
        self.camera_masks: dict[str, torch.Tensor] = {}
        self.params: dict[str, dict[str, Any]] = {}
        self.task_params: dict[str, Any] | None = None
        self._armed = False

    def arm(self, seeds: Sequence[int], record: int = 0) -> None:
        """Start a new batch of episodes with these env seeds; record video frames of the first ``record`` envs."""
        self.seeds = [int(s) for s in seeds]
        self.step = 0
        self.record = min(int(record), len(self.seeds))
        self.frames = []
        self.camera_masks, self.params, self.task_params = {}, {}, None
        self._armed = True

    def _generator(self, seed: int, channel: str) -> torch.Generator:
        return torch.Generator().manual_seed(
            derive_seed(
                self.phantom.seed, self.condition.attack, self.condition.sampled_intensity, seed, channel
            )
        )

    def _draw_camera(self, observation: dict[str, Any]) -> None:
        available = image_keys(observation)
        chosen = resolve_cameras(self.phantom.cameras, available)
        batch = len(self.seeds)
        if chosen is None:
            picks = [
                int(torch.randint(len(available), (1,), generator=self._generator(s, "camera")).item())
                for s in self.seeds
            ]
            self.camera_masks = {k: torch.tensor([p == i for p in picks]) for i, k in enumerate(available)}
            self.camera_masks = {k: m for k, m in self.camera_masks.items() if m.any()}
        else:
            self.camera_masks = {k: torch.ones(batch, dtype=torch.bool) for k in chosen}
        for key in self.camera_masks:
            if observation[key].shape[0] != batch:
                raise RuntimeError(
                    f"armed with {batch} episode seeds but {key} holds {observation[key].shape[0]} images"
                )
            height, width = observation[key].shape[-2:]
            self.params[key] = concat_params(
                [
                    self.attack.sample_params(
                        1,
                        height,
                        width,
                        intensity=self.condition.sampled_intensity,
                        generator=self._generator(s, key),
                    )
                    for s in self.seeds
                ]
            )

    def _draw_task(self) -> None:
        self.task_params = concat_params(
            [
                self.attack.sample_params(
                    1, intensity=self.condition.sampled_intensity, generator=self._generator(s, "task")
                )
                for s in self.seeds
            ]
        )

    def __call__(self, transition: dict) -> dict:
        if not self._armed:
            raise RuntimeError("AttackStep.arm(seeds) must be called before a rollout")
        observation = dict(transition[TransitionKey.OBSERVATION])
        transition = dict(transition)
        if self.attack is not None and self.phantom.is_active(self.step):
            if self.condition.is_camera:
                if not self.params:
                    self._draw_camera(observation)
                for key, mask in self.camera_masks.items():
                    params = self.params[key]
                    if bool(mask.all()):
                        observation[key] = self.attack.apply_params(observation[key], params)
                    else:
                        subset = {n: v[mask] for n, v in params.items()}
                        attacked = observation[key].clone()
                        attacked[mask] = self.attack.apply_params(observation[key][mask], subset)
                        observation[key] = attacked
            else:
                if self.task_params is None:
                    self._draw_task()
                complementary = dict(transition.get(TransitionKey.COMPLEMENTARY_DATA) or {})
                complementary["task"] = self.attack.apply_params(
                    list(complementary["task"]), self.task_params
                )
                transition[TransitionKey.COMPLEMENTARY_DATA] = complementary
        transition[TransitionKey.OBSERVATION] = observation
        if self.record:
            self.frames.append(frames_to_video_frames(observation, image_keys(observation), self.record))
        self.step += 1
        return transition

    def episode_params(self, index: int) -> dict[str, Any]:
        """What eval.json records about episode ``index``'s attack (scalar parameters per attacked channel)."""
        if self.condition.is_camera:
            return {
                key.rsplit(".", 1)[-1]: scalar_params(self.params[key], index)
                for key, mask in self.camera_masks.items()
                if bool(mask[index])
            }
        if self.task_params is not None:
            return {"task": scalar_params(self.task_params, index)}
        return {}

    def transform_features(self, features: dict) -> dict:
        return features  # attacks change pixel values and strings, never shapes or keys


class EpisodeTasks(ProcessorStep):
    """Records which task each env of a batch runs, from the first observation of the batch (before any attack).

    Suites such as phantom_table draw their task per episode from the reset seed, and a vector env auto-resets
    finished envs to new tasks, so the task must be read at the first step. ``instruction`` is the language string
    the policy is given (LeRobot's ``task`` feature); ``task_index``/``task`` are the env's own ``task_id``/``task``
    attributes when it exposes them (None otherwise).
    """

    def __init__(self, env) -> None:
        self.env = env
        self.tasks: list[dict[str, Any]] = []

    def arm(self) -> None:
        self.tasks = []

    def _env_attribute(self, name: str) -> list[Any] | None:
        envs = getattr(self.env, "envs", None)
        if not envs or not envs[0].has_wrapper_attr(name):
            return None
        return list(self.env.call(name))

    def __call__(self, transition: dict) -> dict:
        if not self.tasks:
            instructions = list((transition.get(TransitionKey.COMPLEMENTARY_DATA) or {}).get("task") or [])
            count = self.env.num_envs
            indices = self._env_attribute("task_id") or [None] * count
            names = self._env_attribute("task") or [None] * count
            instructions = instructions or [None] * count
            self.tasks = [
                {"task_index": None if i is None else int(i), "task": n, "instruction": t}
                for i, n, t in zip(indices, names, instructions, strict=True)
            ]
        return transition

    def transform_features(self, features: dict) -> dict:
        return features


def episode_outcomes(rollout_data: dict[str, torch.Tensor]) -> list[dict[str, Any]]:
    """Per-env success, rewards and length of one LeRobot rollout, masked after each env's first done exactly as
    ``lerobot-eval``'s ``eval_policy`` does (the done step and the one after it still count)."""
    done = rollout_data["done"].to(int)
    first_done = torch.argmax(done, dim=1)
    mask = torch.arange(done.shape[1])[None, :] <= (first_done[:, None] + 1)
    rewards = rollout_data["reward"] * mask
    return [
        {
            "success": bool(success),
            "sum_reward": float(total),
            "max_reward": float(peak),
            "steps": int(last) + 1,
        }
        for success, total, peak, last in zip(
            (rollout_data["success"] * mask).any(dim=1).tolist(),
            rewards.sum(dim=1).tolist(),
            rewards.max(dim=1).values.tolist(),
            first_done.tolist(),
            strict=True,
        )
    ]
