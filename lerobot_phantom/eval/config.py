"""Configs of ``lerobot-phantom-eval``: every ``lerobot-eval`` flag plus ``--phantom.*`` (and ``--dataset.*``).

``PhantomEvalConfig`` is LeRobot's ``EvalPipelineConfig`` (``--policy.path``, ``--env.type``, ``--env.task``,
``--eval.n_episodes``, ``--eval.batch_size``, ``--seed``, ``--output_dir``, ...) with two additions:

* ``--phantom.*`` (``EvalPhantomConfig``): which attacks (all eight by default) at which intensities, on which
  cameras, and when (``onset``/``duration`` in env steps). The clean control is always run.
* ``--dataset.*`` (LeRobot's ``DatasetConfig``): offline mode for real-robot data without a simulator; give it
  *instead of* ``--env.*``.
* ``--resume=true``: continue an interrupted run in the same ``--output_dir``, condition by condition.
"""

from __future__ import annotations

import os
from dataclasses import MISSING, dataclass, field
from pathlib import Path

from lerobot.configs import parser
from lerobot.configs.default import DatasetConfig
from lerobot.configs.eval import EvalPipelineConfig
from lerobot.envs.configs import EnvConfig

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.eval.results import CLEAN
from lerobot_phantom.transforms.instruction import MODES as INSTRUCTION_MODES
from lerobot_phantom.transforms.intensity import parse_intensity
from lerobot_phantom.transforms.registry import ATTACK_NAMES

# PhantomConfig fields that only mean something when mixing attacks into training data -> what to use instead.
TRAINING_ONLY = {
    "weights": "--phantom.attacks (every attack is evaluated)",
    "intensity": "--phantom.intensities (one condition per level)",
    "instruction_attacks": "--phantom.attacks, which takes instruction attacks too",
    "instruction_rate": "--phantom.attacks, which takes instruction attacks too",
    "where": "nothing: evaluation attacks the env observations",
}


def training_default(name: str):
    """PhantomConfig's default for field ``name`` (read from the class, so the two never drift apart)."""
    spec = PhantomConfig.__dataclass_fields__[name]
    return spec.default_factory() if spec.default_factory is not MISSING else spec.default


@dataclass
class EvalPhantomConfig(PhantomConfig):
    # Attacks evaluated, each at every intensity below; camera and instruction attacks. 'clean' is implied.
    attacks: list[str] = field(default_factory=lambda: list(ATTACK_NAMES))
    # Intensity levels evaluated ('weak'|'medium'|'strong' or a number in [0, 1]); one condition per level.
    intensities: list[str] = field(default_factory=lambda: ["weak", "medium", "strong"])
    # Instruction attacks: 'paper' (all-or-nothing as in the paper: one condition each) or 'graded' (one per
    # intensity; see lerobot_phantom.transforms.instruction).
    instruction_mode: str = "paper"
    # Environment step at which the attacker switches on (0 = from the first observation).
    onset: int = 0
    # Number of steps the attack lasts from `onset`; None = until the episode ends.
    duration: int | None = None
    # Rollout videos (what the policy sees, attacked cameras included) for the first N episodes of each condition.
    videos: int = 0
    # Offline mode only: at most this many frames of the dataset are compared clean vs attacked (evenly spread).
    offline_frames: int = 256
    # Training-only: every episode of an attacked condition is attacked, so the mixing rate does not apply.
    rate: float = 0.0

    def validate(self) -> None:
        if CLEAN in self.attacks:
            # Accepted for convenience; the clean control is always run once.
            self.attacks = [a for a in self.attacks if a != CLEAN]
        super().validate()
        for name, instead in TRAINING_ONLY.items():
            if getattr(self, name) != training_default(name):
                raise ValueError(f"--phantom.{name} is a training option; in evaluation use {instead}")
        if len(set(self.attacks)) != len(self.attacks):
            raise ValueError(f"--phantom.attacks lists an attack twice: {self.attacks}")
        if not self.intensities and self.attacks:
            raise ValueError("--phantom.intensities is empty; use e.g. '[weak,medium,strong]'")
        for level in self.intensities:
            parse_intensity(level)
        if self.instruction_mode not in INSTRUCTION_MODES:
            raise ValueError(
                f"--phantom.instruction_mode must be one of {INSTRUCTION_MODES}, got {self.instruction_mode!r}"
            )
        if self.onset < 0:
            raise ValueError(f"--phantom.onset must be >= 0 (an env step), got {self.onset}")
        if self.duration is not None and self.duration < 1:
            raise ValueError(
                f"--phantom.duration must be >= 1 step or None (until the end), got {self.duration}"
            )
        if self.videos < 0:
            raise ValueError(f"--phantom.videos must be >= 0, got {self.videos}")
        if self.offline_frames < 1:
            raise ValueError(f"--phantom.offline_frames must be >= 1, got {self.offline_frames}")

    def is_active(self, step: int) -> bool:
        """Whether the attacker is on at env step ``step`` (0-based)."""
        return step >= self.onset and (self.duration is None or step < self.onset + self.duration)


def check_policy_path(policy_path: str | None) -> None:
    """Fail early and clearly on a checkpoint that cannot be loaded, instead of deep inside the hub client."""
    if policy_path is None:
        return
    path = Path(policy_path)
    if path.exists():
        if not (path / "config.json").is_file():
            raise FileNotFoundError(
                f"--policy.path={policy_path} is not a policy checkpoint: expected config.json (and "
                "model.safetensors) in it, e.g. outputs/train/<run>/checkpoints/last/pretrained_model"
            )
        return
    if os.environ.get("HF_HUB_OFFLINE", "0") not in ("0", "", "false", "False"):
        raise FileNotFoundError(
            f"--policy.path={policy_path} does not exist locally and the Hugging Face hub is offline "
            "(HF_HUB_OFFLINE is set); pass a local checkpoint directory"
        )


@dataclass
class PhantomEvalConfig(EvalPipelineConfig):
    # Optional here (unlike lerobot-eval) because offline mode reads --dataset.* instead.
    env: EnvConfig | None = None
    phantom: EvalPhantomConfig = field(default_factory=EvalPhantomConfig)
    dataset: DatasetConfig | None = None
    # Keep the finished conditions of an interrupted run in <output_dir>/eval.json (same policy, env, seeds and
    # --phantom.*) and run only the missing ones. Rollout mode only.
    resume: bool = False

    def __post_init__(self) -> None:
        check_policy_path(parser.get_path_arg("policy"))
        if (self.env is None) == (self.dataset is None):
            raise ValueError(
                "give exactly one of --env.type=... (rollouts in a simulator) or --dataset.repo_id=... "
                "(offline action deviation on recorded frames)"
            )
        super().__post_init__()
