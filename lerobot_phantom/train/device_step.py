"""Device-side attacks (``--phantom.where=device``): a LeRobot processor step that attacks a whole batch at once.

With ``where=device`` the mixer (``PhantomDataset(apply=False)``) only labels samples; this step, run first in the
training preprocessor, applies the labelled camera attacks batched on the policy's device and the instruction
attacks to the batch's task strings. Each sample's parameters are drawn exactly as the dataloader path draws them
(``lerobot_phantom.datasets.camera_attack_params`` from the sample's ``phantom.seed``), so both paths give the same
pixels; only the kernels run once per (attack, camera) group instead of once per sample.

The step is training-only. ``TrainingPreprocessor`` runs it in front of the policy's own preprocessor but saves,
pushes and exposes only that clean preprocessor, so checkpoints never carry an attack step.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import torch

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.datasets import LABEL_KEYS, camera_attack_params
from lerobot_phantom.datasets.mixer import instruction_generator
from lerobot_phantom.datasets.schedule import CAMERA_CHANNEL, INSTRUCTION_CHANNEL
from lerobot_phantom.transforms.registry import ATTACK_NAMES, CLEAN_ID, is_camera_attack, make_attacks

ATTACK_STEP_NAME = "phantom_attack_processor"

_TransitionKey = compat.transition_keys()


def _expand_frames(params: dict[str, torch.Tensor], frames: int) -> dict[str, torch.Tensor]:
    """Per-sample params -> per-frame params for a (B, T, C, H, W) stack (each sample's frames share one set)."""
    if frames == 1:
        return params
    return {key: value.repeat_interleave(frames, dim=0) for key, value in params.items()}


@compat.processor_step_registry().register(name=ATTACK_STEP_NAME)
@dataclass
class PhantomAttackProcessorStep(compat.processor_step_base()):
    """Applies the attacks named by the mixer's ``phantom.*`` labels to a batch (observations and tasks)."""

    phantom: PhantomConfig | dict[str, Any] = field(default_factory=PhantomConfig)
    # The mixer's camera_keys: bit k of ``phantom.camera`` refers to camera_keys[k].
    camera_keys: list[str] = field(default_factory=list)
    device: str = "cpu"

    def __post_init__(self) -> None:
        if isinstance(self.phantom, dict):
            self.phantom = PhantomConfig(**self.phantom)
        config = self.phantom
        # The mixer draws a sample's per-camera parameters in this order (explicit --phantom.cameras keep theirs).
        self._camera_order = config.resolve_cameras(list(self.camera_keys)) if self.camera_keys else []
        self._attacks = make_attacks(
            [*config.attacks, *config.instruction_attacks],
            intensity=config.intensity,
            calibration=config.calibration,
        )

    def _attack(self, attack_id: int) -> Any:
        name = ATTACK_NAMES[attack_id]
        if name not in self._attacks:
            raise ValueError(
                f"batch labelled with attack {name!r}, which is not in --phantom.attacks/instruction_attacks "
                f"({sorted(self._attacks)}); the mixer and this step must share one PhantomConfig"
            )
        return self._attacks[name]

    def __call__(self, transition: dict) -> dict:
        labels = transition.get(_TransitionKey.COMPLEMENTARY_DATA) or {}
        missing = [key for key in LABEL_KEYS if key not in labels]
        if missing:
            raise KeyError(
                f"{ATTACK_STEP_NAME} needs the mixer's labels {missing} in the batch; wrap the dataset in "
                "PhantomDataset(apply=False) and keep the labels through the preprocessor (TrainingPreprocessor)"
            )
        transition = dict(transition)
        transition[_TransitionKey.OBSERVATION] = self.attack_cameras(
            dict(transition.get(_TransitionKey.OBSERVATION) or {}), labels
        )
        if "task" in labels:
            complementary = dict(labels)
            complementary["task"] = self.attack_tasks(labels["task"], labels)
            transition[_TransitionKey.COMPLEMENTARY_DATA] = complementary
        return transition

    # -- camera channel -----------------------------------------------------------------------------------
    def attack_cameras(self, observation: dict[str, Any], labels: dict[str, Any]) -> dict[str, Any]:
        attack_ids = labels["phantom.attack"].tolist()
        masks = labels["phantom.camera"].tolist()
        intensities = labels["phantom.intensity"].tolist()
        seeds = labels["phantom.seed"].tolist()
        device = torch.device(self.device)
        for key in self.camera_keys:
            if key in observation:
                observation[key] = observation[key].to(device)

        for attack_id in sorted({a for a in attack_ids if a != CLEAN_ID}):
            if not is_camera_attack(ATTACK_NAMES[attack_id]):
                continue
            attack = self._attack(attack_id)
            members = [i for i, a in enumerate(attack_ids) if a == attack_id]
            # One generator per sample is drawn from in camera order, so draw each sample's full list once.
            per_sample: dict[int, dict[str, dict[str, torch.Tensor]]] = {}
            for i in members:
                cameras = [k for k in self._camera_order if masks[i] >> self.camera_keys.index(k) & 1]
                missing = [k for k in cameras if k not in observation]
                if missing:
                    raise KeyError(
                        f"batch has no camera key(s) {missing}; observation keys: {sorted(observation)}"
                    )
                sizes = [tuple(observation[k].shape[-2:]) for k in cameras]
                params = camera_attack_params(attack, seeds[i], intensities[i], sizes)
                per_sample[i] = dict(zip(cameras, params, strict=True))
            for key in self.camera_keys:
                rows = [i for i in members if key in per_sample[i]]
                if not rows:
                    continue
                images = observation[key]
                frames = images.shape[1] if images.ndim == 5 else 1
                params = {
                    name: torch.cat([per_sample[i][key][name] for i in rows]).to(device)
                    for name in per_sample[rows[0]][key]
                }
                index = torch.tensor(rows, device=device)
                attacked = attack.apply_params(images[index], _expand_frames(params, frames))
                images = images.clone()
                images[index] = attacked
                observation[key] = images
        return observation

    # -- instruction channel --------------------------------------------------------------------------------
    def attack_tasks(self, tasks: str | list[str], labels: dict[str, Any]) -> str | list[str]:
        single = isinstance(tasks, str)
        tasks = [tasks] if single else list(tasks)
        channels = (
            ("phantom.attack", "phantom.intensity", CAMERA_CHANNEL),
            ("phantom.instruction_attack", "phantom.instruction_intensity", INSTRUCTION_CHANNEL),
        )
        seeds = labels["phantom.seed"].tolist()
        # Main channel first, then the instruction channel: the order the mixer applies them in.
        for id_key, intensity_key, channel in channels:
            for i, (attack_id, intensity) in enumerate(
                zip(labels[id_key].tolist(), labels[intensity_key].tolist(), strict=True)
            ):
                if attack_id == CLEAN_ID or is_camera_attack(ATTACK_NAMES[attack_id]):
                    continue
                attack = self._attack(attack_id)
                params = attack.sample_params(
                    1,
                    intensity=torch.tensor([intensity], dtype=torch.float32),
                    generator=instruction_generator(seeds[i], channel),
                )
                tasks[i] = attack.apply_params([tasks[i]], params)[0]
        return tasks[0] if single else tasks

    # -- ProcessorStep API --------------------------------------------------------------------------------
    def get_config(self) -> dict[str, Any]:
        return {"phantom": asdict(self.phantom), "camera_keys": list(self.camera_keys), "device": self.device}

    def transform_features(self, features):
        return features


def _labels_kept(to_transition):
    """``to_transition`` that also carries the mixer's labels into the transition's complementary data."""

    def convert(batch: dict[str, Any]) -> dict:
        transition = to_transition(batch)
        labels = {key: batch[key] for key in LABEL_KEYS if key in batch}
        if labels:
            complementary = dict(transition.get(_TransitionKey.COMPLEMENTARY_DATA) or {})
            complementary.update(labels)
            transition[_TransitionKey.COMPLEMENTARY_DATA] = complementary
        return transition

    return convert


class TrainingPreprocessor:
    """The training loop's view of the policy preprocessor: labels kept, attack step in front (device mode).

    Calling it on a labelled batch runs ``[attack_step, *pipeline.steps]`` (or just the steps, keeping labels, when
    ``attack_step`` is None); a batch without labels (e.g. an in-training eval rollout) goes through the clean
    pipeline. Every other attribute - ``save_pretrained``, ``push_to_hub``, ``steps``, ... - is the clean
    pipeline's, which is what LeRobot saves with each checkpoint.
    """

    def __init__(self, pipeline: Any, attack_step: PhantomAttackProcessorStep | None = None) -> None:
        self.pipeline = pipeline
        self.attack_step = attack_step
        steps = ([attack_step] if attack_step is not None else []) + list(pipeline.steps)
        self._labelled = type(pipeline)(
            steps=steps,
            name=pipeline.name,
            to_transition=_labels_kept(pipeline.to_transition),
            to_output=pipeline.to_output,
        )

    def __call__(self, batch: dict[str, Any]) -> dict[str, Any]:
        if any(key in batch for key in LABEL_KEYS):
            return self._labelled(batch)
        return self.pipeline(batch)

    def __getattr__(self, name: str) -> Any:
        if name in ("pipeline", "attack_step", "_labelled"):
            raise AttributeError(name)
        return getattr(self.pipeline, name)
