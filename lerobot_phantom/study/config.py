"""The study's one draccus config: small frozen dataclasses, one per stage family.

Every field ends up in a command line of an existing CLI (``lerobot-phantom-collect``, ``-make-vlm``, ``-train``,
``-eval``, ``-report``); ``extra_args`` pass any other flag of that CLI through unchanged. Changing a field changes
the fingerprint of the stages whose command it enters, and of the stages after them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot_phantom.train.make_vlm import VLM_SIZES
from lerobot_phantom.transforms.intensity import parse_intensity
from lerobot_phantom.transforms.registry import ATTACK_NAMES, CAMERA_ATTACKS, INSTRUCTION_ATTACKS

# The CPU recipe for clean training (issue 11); configs/README.md says when to use which config.
CLEAN_TRAIN_CONFIG = "configs/smolvla_goal_cpu.json"
LORA_CONFIG = "configs/smolvla_lora_phantom.json"


@dataclass(frozen=True)
class CollectSettings:
    suite: str = "goal"  # phantom_table suite: the demonstrations' tasks and the evaluated env
    episodes: int = 100  # scripted-expert demonstrations, round-robin over the suite's tasks
    action_noise: float = 0.3  # relative noise on the executed motion (recovery data)
    # share of demonstrations that miss their first grasp on purpose and recover (docs/recipe, run G: 84% vs 50%)
    grasp_miss_rate: float = 0.5
    image_size: int = 96  # camera resolution of the dataset and of the evaluated env
    seed: int = 0
    extra_args: tuple[str, ...] = ()  # further lerobot-phantom-collect flags


@dataclass(frozen=True)
class VLMSettings:
    size: str = "small"  # lerobot-phantom-make-vlm --size: 'tiny' (tests) or 'small' (CPU studies)


@dataclass(frozen=True)
class CleanTrainSettings:
    # lerobot-phantom-train --config_path (relative paths: from the working directory, else the package's repo).
    config_path: str = CLEAN_TRAIN_CONFIG
    steps: int | None = None  # None: the config's
    batch_size: int | None = None  # None: the config's
    # Checkpoint every N steps (an interrupted run resumes from the last one; the final step is always saved).
    save_freq: int | None = None  # None: the config's
    seed: int = 0
    extra_args: tuple[str, ...] = ()  # further lerobot-phantom-train flags


@dataclass(frozen=True)
class SelectSettings:
    """Checkpoint selection: every saved clean checkpoint is evaluated clean on validation seeds (disjoint from the
    sweep's) and the best one is what the sweeps and the LoRA runs start from. Checkpoints 250 steps apart differ
    by up to 30 points of clean TSR on 2 CPU cores (docs/recipe), more than any recipe change measured."""

    enabled: bool = True
    n_episodes: int = 50
    batch_size: int = 10
    seed: int = 5000  # validation episodes use env seeds seed .. seed + n_episodes - 1


@dataclass(frozen=True)
class LoRASettings:
    """Adversarial LoRA fine-tuning from the clean checkpoint (the paper's recipe); the control run uses the same
    settings at rate 0."""

    config_path: str = LORA_CONFIG
    steps: int = 1000
    batch_size: int | None = None  # None: the config's
    save_freq: int = 250  # checkpoints to resume from (the final step is always saved)
    rate: float = 0.3  # fraction of attacked samples (paper: 0.3)
    intensity: str = "random"  # uniform between weak and strong (paper)
    attacks: tuple[str, ...] = tuple(
        CAMERA_ATTACKS
    )  # one drawn at random per attacked sample (paper: the six)
    cameras: tuple[str, ...] = (
        "first",
    )  # --phantom.cameras: 'first' (the paper's front camera), 'all', 'random'
    where: str = "dataloader"  # CPU: attacks in the dataloader; 'device' batches them on a GPU
    lora_rank: int = 16
    seed: int = 0
    extra_args: tuple[str, ...] = ()


@dataclass(frozen=True)
class SweepSettings:
    """The Table-3 sweep run before training, after it and for the control (same seeds: paired episodes)."""

    n_episodes: int = 50
    batch_size: int = 10
    seed: int = 1000
    attacks: tuple[str, ...] = tuple(ATTACK_NAMES)
    intensities: tuple[str, ...] = ("weak", "medium", "strong")
    extra_args: tuple[str, ...] = ()  # further lerobot-phantom-eval flags, e.g. --env.episode_length=...


@dataclass(frozen=True)
class BeyondSettings:
    """Optional stages beyond the paper (off by default)."""

    # Leave-one-attack-out: for each attack listed, LoRA AT on the other camera attacks, evaluated on it.
    leave_one_out: tuple[str, ...] = ()
    # Directory of calibrated.json: AT with the calibrated physics, and both ATs evaluated under both physics.
    calibration: str | None = None
    # Intensities of the calibrated-physics sweeps (default: the sweep's); e.g. [medium,strong] to save time.
    calibration_intensities: tuple[str, ...] | None = None
    # Instruction attacks mixed into AT (e.g. [voice_dos,voice_spoofing]) at this instruction rate.
    instruction_attacks: tuple[str, ...] = ()
    instruction_rate: float = 0.3


@dataclass(frozen=True)
class StudyConfig:
    # Everything the study writes: data/, vlm/, train/, sweeps/, report/, logs/ and study.json.
    output_dir: str = "outputs/study"
    collect: CollectSettings = field(default_factory=CollectSettings)
    vlm: VLMSettings = field(default_factory=VLMSettings)
    train: CleanTrainSettings = field(default_factory=CleanTrainSettings)
    select: SelectSettings = field(default_factory=SelectSettings)
    lora: LoRASettings = field(default_factory=LoRASettings)
    sweep: SweepSettings = field(default_factory=SweepSettings)
    beyond: BeyondSettings = field(default_factory=BeyondSettings)
    # Torch/OpenMP threads per stage process (one is fastest on a busy 2-core machine; issue 11).
    threads: int = 1
    # Stages run at once, each as soon as the stages it depends on are done (2 on 2 cores: the before sweep beside
    # the AT training, then the control training, then the after and control sweeps together). Subprocesses only.
    jobs: int = 1
    # Run each stage in this process instead of a subprocess (tests; the manifest's commands are the same).
    in_process: bool = False
    # Stream each stage's output (progress bars included) to the terminal as well as to logs/<stage>.log.
    verbose: bool = True
    # Only print what each stage would do (skip / resume / run) and exit.
    dry_run: bool = False
    # Copy the finished results (manifest, config, sweeps' eval.json, report, logs of sweeps and report, training
    # configs) of the study in output_dir to this directory and exit without running anything (e.g. docs/study).
    publish_to: str | None = None

    def __post_init__(self) -> None:
        self.validate()

    def validate(self) -> None:
        for name in (*self.sweep.attacks, *self.lora.attacks, *self.beyond.leave_one_out):
            if name not in ATTACK_NAMES:
                raise ValueError(f"unknown attack {name!r}; valid attacks: {', '.join(ATTACK_NAMES)}")
        for name in (*self.lora.attacks, *self.beyond.leave_one_out):
            if name not in CAMERA_ATTACKS:
                raise ValueError(
                    f"--lora.attacks and --beyond.leave_one_out take camera attacks ({', '.join(CAMERA_ATTACKS)}), "
                    f"got {name!r}"
                )
        for name in self.beyond.instruction_attacks:
            if name not in INSTRUCTION_ATTACKS:
                raise ValueError(
                    f"--beyond.instruction_attacks takes {', '.join(INSTRUCTION_ATTACKS)}, got {name!r}"
                )
        for level in (
            *self.sweep.intensities,
            *(self.beyond.calibration_intensities or ()),
            self.lora.intensity,
        ):
            parse_intensity(level)
        if self.sweep.n_episodes < 1 or self.sweep.batch_size < 1:
            raise ValueError("--sweep.n_episodes and --sweep.batch_size must be >= 1")
        if self.select.n_episodes < 1 or self.select.batch_size < 1:
            raise ValueError("--select.n_episodes and --select.batch_size must be >= 1")
        validation = range(self.select.seed, self.select.seed + self.select.n_episodes)
        final = range(self.sweep.seed, self.sweep.seed + self.sweep.n_episodes)
        if self.select.enabled and validation.start < final.stop and final.start < validation.stop:
            raise ValueError(
                f"--select.seed={self.select.seed} makes validation seeds {validation.start}..{validation.stop - 1} "
                f"overlap the sweep's {final.start}..{final.stop - 1}: the selected checkpoint would be scored on "
                "the episodes that chose it; pick disjoint seeds"
            )
        if self.threads < 1:
            raise ValueError(f"--threads must be >= 1, got {self.threads}")
        if self.jobs < 1:
            raise ValueError(f"--jobs must be >= 1, got {self.jobs}")
        if self.jobs > 1 and self.in_process:
            raise ValueError(
                "--jobs > 1 runs stages side by side as subprocesses; it cannot be combined with --in_process"
            )
        if not 0.0 <= self.lora.rate <= 1.0:
            raise ValueError(f"--lora.rate must lie in [0, 1], got {self.lora.rate}")
        if self.vlm.size not in VLM_SIZES:
            raise ValueError(f"--vlm.size must be one of {sorted(VLM_SIZES)}, got {self.vlm.size!r}")
