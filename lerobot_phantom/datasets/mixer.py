"""``PhantomDataset``: mix attacked samples into a LeRobot dataset, exactly and reproducibly.

Wrap a ``LeRobotDataset`` (or anything with its interface: ``__len__``, ``__getitem__`` returning a dict with
camera keys and ``"task"``, optionally ``.meta.camera_keys``)::

    dataset = PhantomDataset(LeRobotDataset(repo_id, root=...), PhantomConfig(rate=0.3))
    dataset.set_epoch(epoch)  # before iterating each epoch; works with persistent dataloader workers

Which samples are attacked, by which attack, how hard and on which camera is planned per epoch by
``schedule.plan_channel``: exact fractions, a pure function of ``(seed, epoch, index)``, so the result does not
depend on the number of dataloader workers or processes. Each sample's attack parameters are drawn from
``torch.Generator().manual_seed(phantom.seed)``: ``camera_attack_params`` is that draw, and a device-side step that
receives the labels (``apply=False``) reproduces the exact pixels with it.

Order with LeRobot's own ``image_transforms`` (augmentation): the sensor is attacked first, augmentation comes
after, as on a robot. ``LeRobotDataset.__getitem__`` applies ``image_transforms`` itself, so at construction
(``apply=True``) the wrapper takes them over: it wraps a shallow copy of the dataset whose ``image_transforms`` is
``None`` (the caller's dataset object is left as it was), attacks the raw frames, and then applies the held
transforms to every camera key, as LeRobot would have. With ``apply=False`` the dataset is not touched at all:
LeRobot applies its transforms as usual and only the labels are added, so a later device-side attack comes after
augmentation.

Labels added to every sample (scalar tensors, batched by the default collate):

* ``phantom.attack`` - int64 ``ATTACK_IDS`` id of the main-channel attack, -1 for clean;
* ``phantom.intensity`` - float32 intensity ``s`` of that attack, 0 for clean;
* ``phantom.camera`` - int64 bitmask over ``camera_keys`` (bit k set: ``camera_keys[k]`` attacked);
* ``phantom.instruction_attack`` / ``phantom.instruction_intensity`` - the instruction channel (-1 / 0 if clean);
* ``phantom.seed`` - int64 seed of the sample's attack parameters.

A main-channel attack that is an instruction attack (``--phantom.attacks`` may list ``voice_dos``) attacks
``task`` instead of a camera (``phantom.camera`` is then 0). The instruction channel (``instruction_attacks``,
``instruction_rate``) is planned independently; when both attack one sample's task, the main channel's attack is
applied first.
"""

from __future__ import annotations

import copy
from functools import partial
from typing import Any

import torch
from torch.utils.data import Dataset

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.datasets.schedule import (
    CAMERA_CHANNEL,
    INSTRUCTION_CHANNEL,
    ChannelPlan,
    plan_channel,
    sample_seed,
)
from lerobot_phantom.transforms.base import derive_seed
from lerobot_phantom.transforms.intensity import is_random, random_intensities
from lerobot_phantom.transforms.registry import ATTACK_IDS, CLEAN_ID, is_camera_attack, make_attacks

LABEL_KEYS = (
    "phantom.attack",
    "phantom.intensity",
    "phantom.camera",
    "phantom.instruction_attack",
    "phantom.instruction_intensity",
    "phantom.seed",
)


def camera_attack_params(
    attack: Any,
    seed: int,
    intensity: float | torch.Tensor,
    image_sizes: list[tuple[int, int]],
    device: torch.device | str | None = None,
) -> list[dict[str, torch.Tensor]]:
    """The parameters of one sample's camera attack, one set per attacked camera (in ``camera_keys`` order).

    One generator, ``torch.Generator().manual_seed(seed)``, is drawn from in camera order; every set has leading
    dim 1, so it broadcasts over the frames of a ``delta_timestamps`` stack. This is the single definition both
    the dataloader path and a device-side step use.
    """
    generator = torch.Generator().manual_seed(int(seed))
    s = torch.as_tensor(intensity, dtype=torch.float32).reshape(1)
    return [
        attack.sample_params(1, height, width, intensity=s, generator=generator, device=device)
        for height, width in image_sizes
    ]


def instruction_generator(seed: int, channel: str) -> torch.Generator:
    """Generator of one sample's instruction-attack parameters (kept apart from the camera draws)."""
    return torch.Generator().manual_seed(derive_seed("phantom-instruction", int(seed), channel))


class _Schedule:
    """Per-epoch plans of both channels; recomputed lazily in each process when the epoch changes.

    With ``intensity="random"`` each attack's stratified draws follow its adversarial-training distribution (its
    ``random_parameter``, as the attack's own ``"random"`` draws), not a uniform ``s``.
    """

    def __init__(
        self, config: PhantomConfig, num_items: int, num_camera_slots: int, attacks: dict[str, Any]
    ) -> None:
        self.config = config
        self.num_items = num_items
        self.num_camera_slots = num_camera_slots
        self.quantiles = {
            CAMERA_CHANNEL: self._quantiles(config.attacks, attacks),
            INSTRUCTION_CHANNEL: self._quantiles(config.instruction_attacks, attacks),
        }
        self._epoch: int | None = None
        self._plans: dict[str, ChannelPlan] = {}

    def __getstate__(self) -> dict[str, Any]:
        # Plans are cheap to recompute and O(N): dataloader workers rebuild them instead of receiving copies.
        return {**self.__dict__, "_epoch": None, "_plans": {}}

    def _quantiles(self, names: list[str], attacks: dict[str, Any]) -> list[Any] | None:
        if not names or not is_random(self.config.intensity):
            return None
        return [partial(random_intensities, attacks[name]) for name in names]

    def plans(self, epoch: int) -> dict[str, ChannelPlan]:
        if epoch != self._epoch:
            config = self.config
            self._plans = {
                CAMERA_CHANNEL: plan_channel(
                    self.num_items,
                    rate=config.rate if config.attacks else 0.0,
                    weights=config.attack_weights or [1.0],
                    intensity_range=config.intensity_range,
                    seed=config.seed,
                    epoch=epoch,
                    channel=CAMERA_CHANNEL,
                    num_camera_slots=self.num_camera_slots,
                    quantiles=self.quantiles[CAMERA_CHANNEL],
                ),
                INSTRUCTION_CHANNEL: plan_channel(
                    self.num_items,
                    rate=config.instruction_rate if config.instruction_attacks else 0.0,
                    weights=[1.0] * max(1, len(config.instruction_attacks)),
                    intensity_range=config.intensity_range,
                    seed=config.seed,
                    epoch=epoch,
                    channel=INSTRUCTION_CHANNEL,
                    quantiles=self.quantiles[INSTRUCTION_CHANNEL],
                ),
            }
            self._epoch = epoch
        return self._plans


class PhantomDataset(Dataset):
    """Attack-mixing wrapper; see the module docstring."""

    def __init__(
        self,
        dataset: Any,
        config: PhantomConfig,
        *,
        camera_keys: list[str] | None = None,
        apply: bool = True,
        rank: int = 0,
        world_size: int = 1,
    ) -> None:
        config.validate()
        if world_size < 1 or not (0 <= rank < world_size):
            raise ValueError(f"need 0 <= rank < world_size, got rank={rank}, world_size={world_size}")
        if camera_keys is None:
            meta = getattr(dataset, "meta", None)
            if meta is None or not hasattr(meta, "camera_keys"):
                raise ValueError(
                    f"{type(dataset).__name__} has no .meta.camera_keys; pass camera_keys= explicitly"
                )
            camera_keys = list(meta.camera_keys)
        self.camera_keys: list[str] = list(camera_keys)
        self.config = config
        self.apply = apply
        # The decision never depends on rank: each rank's sampler hands it global indices. Kept for logging.
        self.rank = rank
        self.world_size = world_size

        if self.camera_keys:
            self.attack_cameras: list[str] = config.resolve_cameras(self.camera_keys)
        elif config.camera_attacks and config.rate > 0:
            raise ValueError(
                f"camera attacks {config.camera_attacks} need camera keys, but the dataset has none "
                "(pass camera_keys= or attack instructions only)"
            )
        else:
            self.attack_cameras = []
        self._camera_bits = {key: 1 << self.camera_keys.index(key) for key in self.attack_cameras}

        # Built once here so that a bad name or calibration fails now, not in a worker at step 10 000.
        self.attacks: dict[str, Any] = make_attacks(
            [*config.attacks, *config.instruction_attacks],
            intensity=config.intensity,
            calibration=config.calibration,
        )

        self.image_transforms = None
        if apply and getattr(dataset, "image_transforms", None) is not None:
            self.image_transforms = dataset.image_transforms
            dataset = copy.copy(dataset)
            dataset.image_transforms = None
        self.dataset = dataset

        self._num_items = len(dataset)
        self._schedule = _Schedule(
            config,
            self._num_items,
            max(1, len(self.attack_cameras)) if config.random_camera else 1,
            self.attacks,
        )
        # Shared memory, so that set_epoch in the main process reaches persistent dataloader workers too.
        self._epoch = torch.zeros((), dtype=torch.int64).share_memory_()

    # -- epoch ------------------------------------------------------------------------------------------
    @property
    def epoch(self) -> int:
        return int(self._epoch.item())

    def set_epoch(self, epoch: int) -> None:
        """Advance the schedule; call before each epoch's iteration starts (like ``DistributedSampler``)."""
        if int(epoch) < 0:
            raise ValueError(f"epoch must be >= 0, got {epoch}")
        self._epoch.fill_(int(epoch))

    # -- decisions ----------------------------------------------------------------------------------------
    def decision(self, index: int, epoch: int | None = None) -> dict[str, Any]:
        """What happens to sample ``index`` in ``epoch`` (default: the current one). Pure in (seed, epoch, index)."""
        index = int(index)
        if not (0 <= index < self._num_items):
            raise IndexError(f"index {index} out of range for a dataset of {self._num_items} samples")
        epoch = self.epoch if epoch is None else int(epoch)
        plans = self._schedule.plans(epoch)
        config = self.config

        main = plans[CAMERA_CHANNEL]
        slot = int(main.choice[index])
        attack = None if slot < 0 else config.attacks[slot]
        cameras: list[str] = []
        if attack is not None and is_camera_attack(attack):
            if config.random_camera:
                cameras = [self.attack_cameras[int(main.camera_slot[index])]]
            else:
                cameras = list(self.attack_cameras)

        instruction = plans[INSTRUCTION_CHANNEL]
        instruction_slot = int(instruction.choice[index])
        instruction_attack = None if instruction_slot < 0 else config.instruction_attacks[instruction_slot]
        return {
            "index": index,
            "epoch": epoch,
            "attack": attack,
            "attack_id": CLEAN_ID if attack is None else ATTACK_IDS[attack],
            "intensity": float(main.intensity[index]),
            "cameras": cameras,
            "camera_mask": sum(self._camera_bits[key] for key in cameras),
            "instruction_attack": instruction_attack,
            "instruction_attack_id": CLEAN_ID
            if instruction_attack is None
            else ATTACK_IDS[instruction_attack],
            "instruction_intensity": float(instruction.intensity[index]),
            "seed": sample_seed(config.seed, epoch, index),
        }

    # -- Dataset --------------------------------------------------------------------------------------------
    def __len__(self) -> int:
        return self._num_items

    def __getitem__(self, index: int) -> dict[str, Any]:
        item = self.dataset[index]
        choice = self.decision(index)
        if self.apply:
            self.attack_item(item, choice)
            if self.image_transforms is not None:
                for key in self.camera_keys:
                    item[key] = self.image_transforms(item[key])
        item.update(self.labels(choice))
        return item

    @staticmethod
    def labels(choice: dict[str, Any]) -> dict[str, torch.Tensor]:
        """The ``phantom.*`` label tensors of a decision."""
        return {
            "phantom.attack": torch.tensor(choice["attack_id"], dtype=torch.int64),
            "phantom.intensity": torch.tensor(choice["intensity"], dtype=torch.float32),
            "phantom.camera": torch.tensor(choice["camera_mask"], dtype=torch.int64),
            "phantom.instruction_attack": torch.tensor(choice["instruction_attack_id"], dtype=torch.int64),
            "phantom.instruction_intensity": torch.tensor(
                choice["instruction_intensity"], dtype=torch.float32
            ),
            "phantom.seed": torch.tensor(choice["seed"], dtype=torch.int64),
        }

    def attack_item(self, item: dict[str, Any], choice: dict[str, Any]) -> None:
        """Apply ``choice`` (a ``decision``) to ``item`` in place: its cameras and/or its task."""
        name = choice["attack"]
        try:
            if name is not None and choice["cameras"]:
                self._attack_cameras(item, choice)
            elif name is not None:
                self._attack_task(item, name, choice["intensity"], choice["seed"], CAMERA_CHANNEL)
            if choice["instruction_attack"] is not None:
                self._attack_task(
                    item,
                    choice["instruction_attack"],
                    choice["instruction_intensity"],
                    choice["seed"],
                    INSTRUCTION_CHANNEL,
                )
        except Exception as err:
            err.add_note(
                f"lerobot-phantom: while attacking sample index {choice['index']} (epoch {choice['epoch']}, "
                f"attack {name!r} at intensity {choice['intensity']:.4f} on {choice['cameras']}, instruction "
                f"attack {choice['instruction_attack']!r}, sample seed {choice['seed']}, config seed "
                f"{self.config.seed})"
            )
            raise

    def _attack_cameras(self, item: dict[str, Any], choice: dict[str, Any]) -> None:
        missing = [key for key in choice["cameras"] if key not in item]
        if missing:
            raise KeyError(f"sample has no camera key(s) {missing}; its keys are {sorted(item)}")
        frames = [item[key] for key in choice["cameras"]]
        attack = self.attacks[choice["attack"]]
        params = camera_attack_params(
            attack,
            choice["seed"],
            choice["intensity"],
            [tuple(frame.shape[-2:]) for frame in frames],
            device=frames[0].device,
        )
        for key, frame, frame_params in zip(choice["cameras"], frames, params, strict=True):
            item[key] = attack.apply_params(frame, frame_params)

    def _attack_task(
        self, item: dict[str, Any], name: str, intensity: float, seed: int, channel: str
    ) -> None:
        if "task" not in item:
            raise KeyError(
                f"instruction attack {name!r} needs a 'task' string; the sample's keys are {sorted(item)}"
            )
        attack = self.attacks[name]
        params = attack.sample_params(
            1,
            intensity=torch.tensor([intensity], dtype=torch.float32),
            generator=instruction_generator(seed, channel),
        )
        item["task"] = attack.apply_params([item["task"]], params)[0]

    # -- passthrough ----------------------------------------------------------------------------------------
    def __getattr__(self, name: str) -> Any:
        # Only reached for names the wrapper lacks (meta, features, num_frames, episodes, fps, ...). The guard
        # keeps unpickling (no "dataset" yet) from recursing.
        if name.startswith("__") or name == "dataset":
            raise AttributeError(name)
        dataset = self.__dict__.get("dataset")
        if dataset is None:
            raise AttributeError(name)
        return getattr(dataset, name)

    def __repr__(self) -> str:
        return (
            f"PhantomDataset(rate={self.config.rate}, attacks={self.config.attacks}, cameras={self.attack_cameras}, "
            f"instruction_rate={self.config.instruction_rate}, seed={self.config.seed}, epoch={self.epoch}, "
            f"apply={self.apply}, dataset={self.dataset!r})"
        )
