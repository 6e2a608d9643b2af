"""``PhantomConfig``: the ``--phantom.*`` flag group shared by every lerobot-phantom CLI.

Training and offline augmentation use ``rate``/``instruction_rate``/``where``; evaluation extends this class with
its own fields (see ``lerobot_phantom.eval``). Lists are written the way LeRobot's CLI takes them, e.g.
``--phantom.attacks='[laser_blinding,voice_dos]'``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from lerobot_phantom.transforms.intensity import parse_intensity
from lerobot_phantom.transforms.registry import ATTACK_NAMES, CAMERA_ATTACKS, INSTRUCTION_ATTACKS

CAMERA_MODES = ("first", "all", "random")
WHERE_CHOICES = ("dataloader", "device")


@dataclass
class PhantomConfig:
    # Fraction of samples that are attacked (exact over an epoch, not merely in expectation).
    rate: float = 0.3
    # Attacks drawn from, uniformly unless `weights` is given. Camera and/or instruction attacks.
    attacks: list[str] = field(default_factory=lambda: list(CAMERA_ATTACKS))
    # Optional relative weight per entry of `attacks` (same length).
    weights: list[float] | None = None
    # 'random' (uniform between weak and strong), 'weak'|'medium'|'strong', '0.5', or a range '0.2:0.8'.
    intensity: str = "random"
    # Which camera key(s) an attacked sample has attacked: ['first'] (the paper: the front camera), ['all'],
    # ['random'] (one camera at random), or explicit keys such as ['observation.images.front'].
    cameras: list[str] = field(default_factory=lambda: ["first"])
    # Instruction attacks drawn for the instruction channel, independently of the camera attack.
    instruction_attacks: list[str] = field(default_factory=list)
    # Fraction of samples whose instruction is attacked (exact over an epoch).
    instruction_rate: float = 0.0
    # Seed of every random choice (which samples, which attack, which intensity, attack parameters).
    seed: int = 0
    # Optional directory holding calibrated.json (written by lerobot-phantom-calibrate).
    calibration: str | None = None
    # Where camera attacks run during training: in dataloader workers, or batched on the policy's device.
    where: str = "dataloader"

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        for name in ("rate", "instruction_rate"):
            value = getattr(self, name)
            if (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not (0.0 <= float(value) <= 1.0)
            ):
                raise ValueError(f"--phantom.{name} must be a number in [0, 1], got {value!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int):
            raise ValueError(f"--phantom.seed must be an integer, got {self.seed!r}")
        for group in ("attacks", "instruction_attacks", "cameras"):
            values = getattr(self, group)
            duplicates = sorted({v for v in values if values.count(v) > 1})
            if duplicates:
                raise ValueError(f"--phantom.{group} lists {duplicates} more than once: {values}")
        for name in (*self.attacks, *self.instruction_attacks):
            if name not in ATTACK_NAMES:
                raise ValueError(
                    f"unknown attack {name!r} in --phantom.*; valid attacks: {', '.join(ATTACK_NAMES)}"
                )
        for name in self.instruction_attacks:
            if name not in INSTRUCTION_ATTACKS:
                raise ValueError(
                    f"--phantom.instruction_attacks takes instruction attacks only ({', '.join(INSTRUCTION_ATTACKS)}), "
                    f"got {name!r}"
                )
        if self.weights is not None:
            if len(self.weights) != len(self.attacks):
                raise ValueError(
                    f"--phantom.weights needs one weight per attack ({len(self.attacks)}: {self.attacks}), "
                    f"got {len(self.weights)}"
                )
            if any(not math.isfinite(w) or w < 0 for w in self.weights) or sum(self.weights) <= 0:
                raise ValueError(f"--phantom.weights must be >= 0 with a positive sum, got {self.weights}")
        parse_intensity(self.intensity)
        if not self.cameras:
            raise ValueError(f"--phantom.cameras must not be empty; use one of {CAMERA_MODES} or camera keys")
        if len(self.cameras) > 1 and any(c in CAMERA_MODES for c in self.cameras):
            raise ValueError(f"--phantom.cameras: {CAMERA_MODES} stand alone, got {self.cameras}")
        if self.where not in WHERE_CHOICES:
            raise ValueError(f"--phantom.where must be one of {WHERE_CHOICES}, got {self.where!r}")
        if self.rate > 0 and not self.attacks:
            raise ValueError("--phantom.attacks is empty but --phantom.rate > 0")
        if self.instruction_rate > 0 and not self.instruction_attacks:
            raise ValueError("--phantom.instruction_rate > 0 needs --phantom.instruction_attacks")

    @property
    def intensity_range(self) -> tuple[float, float]:
        return parse_intensity(self.intensity)

    @property
    def camera_attacks(self) -> list[str]:
        return [a for a in self.attacks if a in CAMERA_ATTACKS]

    @property
    def attack_weights(self) -> list[float]:
        """Relative weight of each entry of ``attacks`` (uniform when ``weights`` is unset)."""
        return [1.0] * len(self.attacks) if self.weights is None else [float(w) for w in self.weights]

    def resolve_cameras(self, camera_keys: list[str]) -> list[str]:
        """The camera keys ``cameras`` can attack, for a dataset with ``camera_keys`` (order kept).

        ``first`` -> ``[camera_keys[0]]``; ``all`` and ``random`` -> every key (``random`` then picks one per
        sample); explicit keys are checked against the dataset's.
        """
        if not camera_keys:
            raise ValueError("the dataset has no camera keys, so --phantom.cameras cannot be resolved")
        mode = self.cameras[0]
        if mode == "first":
            return [camera_keys[0]]
        if mode in ("all", "random"):
            return list(camera_keys)
        unknown = [c for c in self.cameras if c not in camera_keys]
        if unknown:
            raise ValueError(
                f"--phantom.cameras: unknown camera key(s) {unknown}; this dataset's camera keys are "
                f"{list(camera_keys)} (or use one of {CAMERA_MODES})"
            )
        return list(self.cameras)

    @property
    def random_camera(self) -> bool:
        """True when each attacked sample gets one camera chosen at random among the resolved keys."""
        return self.cameras == ["random"]
