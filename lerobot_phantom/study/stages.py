"""The study's stages: what each one runs (an existing CLI's command line), what it writes, what it needs, and
whether an earlier invocation already did it.

A stage is a command line plus its output directory, both relative to the study directory (the commands run there,
so ``study.json`` shows commands a user can type from it). Its fingerprint hashes the command (with every config
file it reads replaced by a hash of the file's content) and the fingerprints of the stages it depends on, so a
changed setting re-runs that stage and everything downstream of it, and nothing else.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import lerobot_phantom
from lerobot_phantom.envs.suites import SUITES
from lerobot_phantom.eval.tables import ATTACK_TITLES
from lerobot_phantom.study.config import StudyConfig
from lerobot_phantom.transforms.calibrated import calibrated_options, calibration_set
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS

COLLECT, VLM, TRAIN, SWEEP, SELECT, REPORT = "collect", "vlm", "train", "sweep", "select", "report"
PRETRAINED = "checkpoints/last/pretrained_model"
EVAL_FILE = "eval.json"
SELECTION_FILE = "selection.json"
CLEAN_RUN, SELECTED_RUN = "train/clean", "train/selected"

# Decisions for a stage at the start of an invocation.
SKIP, RESUME, RUN = "skip", "resume", "run"


@dataclass(frozen=True)
class Stage:
    name: str
    kind: str  # collect | vlm | train | sweep | select | report
    command: str  # the console script
    args: tuple[str, ...]
    output: str  # the stage's own directory, relative to the study directory
    depends: tuple[str, ...] = ()
    files: tuple[str, ...] = ()  # config files outside the study the command reads (hashed by content)
    # Files the command reads through a directory flag (a calibration set): their content enters the fingerprint.
    inputs: tuple[str, ...] = ()
    # Sweeps: the name under which study.json's "results" lists the eval file (None: a validation run).
    role: str | None = None

    @property
    def argv(self) -> list[str]:
        return [self.command, *self.args]

    def resume_argv(self) -> list[str]:
        """The command that continues an interrupted run of this stage."""
        if self.kind == TRAIN:
            return [
                self.command,
                f"--config_path={self.output}/{PRETRAINED}/train_config.json",
                "--resume=true",
            ]
        if self.kind == SWEEP:
            return [*self.argv, "--resume=true"]
        raise ValueError(f"stage {self.name} ({self.kind}) cannot resume; it re-runs")


def role_label(role: str) -> str:
    """How the report names a sweep role (``at_without_em_color_strip`` -> ``AT without EM color strip``)."""
    named = {
        "before": "before",
        "after": "AT",
        "control": "control",
        "at_calibrated": "measured-physics AT",
        "at_instruction": "AT + instruction attacks",
    }
    policy = role.removesuffix("_calibrated_physics")
    if policy.startswith("at_without_"):
        label = "AT without " + ATTACK_TITLES[policy.removeprefix("at_without_")]
    else:
        label = named.get(policy, policy)
    return f"{label} under measured physics" if policy != role else label


def file_digest(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def fingerprint(stage: Stage, upstream: dict[str, str]) -> str:
    """Hash of the stage's command (config files by content, not path) and of its dependencies' fingerprints."""
    args = list(stage.args)
    for path in stage.files:
        args = [a.replace(path, f"sha256:{file_digest(path)}") for a in args]
    payload = {"command": stage.command, "args": args, "upstream": [upstream[d] for d in stage.depends]}
    if stage.inputs:
        payload["inputs"] = {path: file_digest(path) for path in stage.inputs}
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]


def fingerprints(stages: list[Stage]) -> dict[str, str]:
    out: dict[str, str] = {}
    for stage in stages:  # stages come in dependency order
        out[stage.name] = fingerprint(stage, out)
    return out


# --------------------------------------------------------------------------------------------------------------
# completion and decisions
# --------------------------------------------------------------------------------------------------------------
def is_complete(stage: Stage, study_dir: Path) -> bool:
    """Whether the stage's outputs on disk are whole (independent of what study.json says)."""
    out = study_dir / stage.output
    if stage.kind == COLLECT:
        return (out / "meta" / "info.json").is_file()
    if stage.kind == VLM:
        return (out / "config.json").is_file()
    if stage.kind == TRAIN:
        return (out / PRETRAINED / "config.json").is_file()
    if stage.kind == SWEEP:
        path = out / EVAL_FILE
        return path.is_file() and bool(json.loads(path.read_text())["metadata"].get("complete"))
    if stage.kind == SELECT:
        return (out / SELECTION_FILE).is_file() and (out / PRETRAINED / "config.json").is_file()
    return (out / "summary.md").is_file()


def can_resume(stage: Stage, study_dir: Path) -> bool:
    """Whether an interrupted run left something to continue from (a checkpoint, finished conditions)."""
    out = study_dir / stage.output
    if stage.kind == TRAIN:
        return (out / PRETRAINED / "train_config.json").is_file()
    if stage.kind == SWEEP:
        return (out / EVAL_FILE).is_file()
    return False


def decide(
    stage: Stage, fp: str, record: dict[str, Any] | None, study_dir: Path, upstream_ran: bool = False
) -> str:
    """SKIP a finished stage with the same fingerprint; RESUME an interrupted one with the same fingerprint when
    it can; otherwise RUN it from scratch. A stage whose inputs were (re)made in this invocation always runs."""
    same = record is not None and record.get("fingerprint") == fp and not upstream_ran
    if same and record.get("status") == "done" and is_complete(stage, study_dir):
        return SKIP
    if same and record.get("status") == "running" and can_resume(stage, study_dir):
        return RESUME
    return RUN


# --------------------------------------------------------------------------------------------------------------
# the plan
# --------------------------------------------------------------------------------------------------------------
def flag_list(values) -> str:
    """A list flag value as JSON (the one list syntax LeRobot's parser accepts next to --config_path)."""
    return json.dumps(list(values), separators=(",", ":"))


def resolve_config(path: str) -> str:
    """An absolute config path: as given, else relative to the working directory, else to the package's repo
    (``configs/`` of an editable install)."""
    candidate = Path(path)
    if candidate.is_file():
        return str(candidate.resolve())
    in_repo = Path(lerobot_phantom.__file__).resolve().parents[1] / path
    if in_repo.is_file():
        return str(in_repo)
    raise FileNotFoundError(
        f"training config {path} not found (relative to {Path.cwd()} or the package's repo)"
    )


class Planner:
    """Builds the stages of one study config."""

    def __init__(self, cfg: StudyConfig) -> None:
        self.cfg = cfg
        self.stages: list[Stage] = []
        self.repo_id = f"local/phantom_{cfg.collect.suite}"
        self.clean_config = resolve_config(cfg.train.config_path)
        self.lora_config = resolve_config(cfg.lora.config_path)
        # The clean policy everything downstream starts from: the selected checkpoint, or the last one.
        self.start_stage = "select_clean" if cfg.select.enabled else "train_clean"
        self.run_dirs = {"train_clean": CLEAN_RUN, "select_clean": SELECTED_RUN}

    def add(self, *args, **kwargs) -> Stage:
        stage = Stage(*args, **kwargs)
        self.stages.append(stage)
        return stage

    def run_dir(self, stage_name: str) -> str:
        return self.run_dirs.get(stage_name, f"train/{stage_name.removeprefix('train_')}")

    def env_args(self) -> list[str]:
        c = self.cfg.collect
        return [
            "--env.type=phantom_table",
            f"--env.task={c.suite}",
            f"--env.observation_height={c.image_size}",
            f"--env.observation_width={c.image_size}",
        ]

    def dataset_args(self) -> list[str]:
        return [f"--dataset.repo_id={self.repo_id}", "--dataset.root=data/demos"]

    def collect(self) -> None:
        c = self.cfg.collect
        args = [
            f"--suite={c.suite}",
            f"--episodes={c.episodes}",
            f"--repo-id={self.repo_id}",
            "--root=data/demos",
            f"--seed={c.seed}",
            f"--action-noise={c.action_noise}",
            f"--grasp-miss-rate={c.grasp_miss_rate}",
            f"--image-size={c.image_size}",
            *c.extra_args,
        ]
        self.add(COLLECT, COLLECT, "lerobot-phantom-collect", tuple(args), "data/demos")
        instructions = flag_list(dict.fromkeys(t["language"] for t in SUITES[c.suite]))
        args = ["--out=vlm", f"--size={self.cfg.vlm.size}", f"--tasks={instructions}"]
        self.add(VLM, VLM, "lerobot-phantom-make-vlm", tuple(args), "vlm")

    def clean_training(self) -> None:
        t = self.cfg.train
        args = [
            f"--config_path={self.clean_config}",
            *self.dataset_args(),
            # Absolute: the path is saved in the checkpoint, which the demo and users load from other directories.
            f"--policy.vlm_model_name={Path(self.cfg.output_dir).resolve() / 'vlm'}",
            f"--output_dir={CLEAN_RUN}",
            "--phantom.rate=0",
            f"--seed={t.seed}",
            *([f"--steps={t.steps}"] if t.steps is not None else []),
            *([f"--save_freq={t.save_freq}"] if t.save_freq is not None else []),
            *([f"--batch_size={t.batch_size}"] if t.batch_size is not None else []),
            *t.extra_args,
        ]
        self.add(
            "train_clean",
            TRAIN,
            "lerobot-phantom-train",
            tuple(args),
            CLEAN_RUN,
            (COLLECT, VLM),
            (self.clean_config,),
        )

    def checkpoint_steps(self) -> list[int]:
        """The steps at which the clean run saves a checkpoint (LeRobot: every save_freq steps and the last)."""
        t = self.cfg.train
        recipe = json.loads(Path(self.clean_config).read_text())
        steps = t.steps if t.steps is not None else recipe["steps"]
        save_freq = t.save_freq if t.save_freq is not None else recipe["save_freq"]
        marks = list(range(save_freq, steps + 1, save_freq))
        return marks if marks and marks[-1] == steps else [*marks, steps]

    def selection(self) -> None:
        """Every clean checkpoint evaluated clean on the validation seeds, then the best one copied."""
        from lerobot.utils.train_utils import get_step_identifier

        sel = self.cfg.select
        steps = self.checkpoint_steps()
        evals, checkpoints, names = [], [], []
        for step in steps:
            ident = get_step_identifier(step, steps[-1])
            checkpoint = f"{CLEAN_RUN}/checkpoints/{ident}/pretrained_model"
            output = f"sweeps/validation/{ident}"
            args = [
                f"--policy.path={checkpoint}",
                *self.env_args(),
                f"--eval.n_episodes={sel.n_episodes}",
                f"--eval.batch_size={min(sel.batch_size, sel.n_episodes)}",
                f"--seed={sel.seed}",
                "--phantom.attacks=[]",  # clean only
                f"--output_dir={output}",
                *self.cfg.sweep.extra_args,
            ]
            stage = self.add(
                f"sweep_validation_{ident}",
                SWEEP,
                "lerobot-phantom-eval",
                tuple(args),
                output,
                ("train_clean",),
            )
            evals.append(f"{output}/{EVAL_FILE}")
            checkpoints.append(checkpoint)
            names.append(stage.name)
        args = [
            f"--evals={flag_list(evals)}",
            f"--checkpoints={flag_list(checkpoints)}",
            f"--output_dir={SELECTED_RUN}",
        ]
        self.add(
            "select_clean",
            SELECT,
            "lerobot-phantom-select-checkpoint",
            tuple(args),
            SELECTED_RUN,
            tuple(names),
        )

    def lora(self, name: str, rate: float, attacks, *extra: str, inputs: tuple[str, ...] = ()) -> None:
        """LoRA fine-tuning from the clean checkpoint (rate 0: the control)."""
        lo = self.cfg.lora
        args = [
            f"--config_path={self.lora_config}",
            f"--policy.path={self.run_dir(self.start_stage)}/{PRETRAINED}",
            *self.dataset_args(),
            f"--output_dir=train/{name}",
            f"--steps={lo.steps}",
            f"--save_freq={lo.save_freq}",
            f"--seed={lo.seed}",
            f"--peft.r={lo.lora_rank}",
            f"--phantom.rate={rate}",
            f"--phantom.attacks={flag_list(attacks)}",
            f"--phantom.intensity={lo.intensity}",
            f"--phantom.cameras={flag_list(lo.cameras)}",
            f"--phantom.where={lo.where}",
            f"--phantom.seed={lo.seed}",
            "--num_workers=0",
            "--wandb.enable=false",
            *([f"--batch_size={lo.batch_size}"] if lo.batch_size is not None else []),
            *extra,
            *lo.extra_args,
        ]
        self.add(
            f"train_{name}",
            TRAIN,
            "lerobot-phantom-train",
            tuple(args),
            f"train/{name}",
            (self.start_stage,),
            (self.lora_config,),
            inputs=inputs,
        )

    def sweep(
        self,
        role: str,
        policy_stage: str,
        attacks=None,
        *extra: str,
        intensities=None,
        inputs: tuple[str, ...] = (),
    ) -> None:
        s = self.cfg.sweep
        args = [
            f"--policy.path={self.run_dir(policy_stage)}/{PRETRAINED}",
            *self.env_args(),
            f"--eval.n_episodes={s.n_episodes}",
            f"--eval.batch_size={min(s.batch_size, s.n_episodes)}",
            f"--seed={s.seed}",
            f"--phantom.attacks={flag_list(s.attacks if attacks is None else attacks)}",
            f"--phantom.intensities={flag_list(s.intensities if intensities is None else intensities)}",
            f"--output_dir=sweeps/{role}",
            *extra,
            *s.extra_args,
        ]
        self.add(
            f"sweep_{role}",
            SWEEP,
            "lerobot-phantom-eval",
            tuple(args),
            f"sweeps/{role}",
            (policy_stage,),
            role=role,
            inputs=inputs,
        )

    def beyond(self) -> None:
        b, lo = self.cfg.beyond, self.cfg.lora
        for held_out in b.leave_one_out:
            name = f"at_without_{held_out}"
            self.lora(name, lo.rate, [a for a in lo.attacks if a != held_out])
            self.sweep(name, f"train_{name}", [held_out])
        if b.calibration is not None:
            calibration = str(Path(b.calibration).resolve())
            physics = f"--phantom.calibration={calibration}"
            inputs = tuple(str(path) for path, _ in calibration_set(calibration).values())
            # Only the attacks the calibration changes: under the others both physics, and so the outcomes on the
            # same seeds, are the same.
            camera = [a for a in self.cfg.sweep.attacks if a in CAMERA_ATTACKS]
            calibrated = list(calibrated_options(camera, calibration))
            self.lora("at_calibrated", lo.rate, lo.attacks, physics, inputs=inputs)
            levels = b.calibration_intensities
            self.sweep("at_calibrated", "train_at_calibrated", calibrated, intensities=levels)
            # the rate-0 control too: whether AT helps or hurts under the measured physics is judged against the
            # same amount of clean fine-tuning, as under the paper's
            for role, policy in (
                ("before", self.start_stage),
                ("after", "train_at"),
                ("control", "train_control"),
                ("at_calibrated", "train_at_calibrated"),
            ):
                self.sweep(
                    f"{role}_calibrated_physics",
                    policy,
                    calibrated,
                    physics,
                    intensities=levels,
                    inputs=inputs,
                )
        if b.instruction_attacks:
            self.lora(
                "at_instruction",
                lo.rate,
                lo.attacks,
                f"--phantom.instruction_attacks={flag_list(b.instruction_attacks)}",
                f"--phantom.instruction_rate={b.instruction_rate}",
            )
            # Clean TSR and the instruction attacks are what mixing them in can change (issue 11, item 3).
            self.sweep("at_instruction", "train_at_instruction", b.instruction_attacks)

    def report(self) -> None:
        sweeps = {s.role: s for s in self.stages if s.kind == SWEEP and s.role is not None}
        inputs = [role for role in sweeps if not role.endswith("_calibrated_physics")]
        pairs = [("before", "after"), ("control", "after")]
        pairs += [
            ("before", role)
            for role in sweeps
            if role.startswith("at_") and not role.endswith("_calibrated_physics")
        ]
        if "before_calibrated_physics" in sweeps:
            pairs += [
                ("before_calibrated_physics", r)
                for r in ("after_calibrated_physics", "at_calibrated_calibrated_physics")
            ]
            pairs += [
                ("control_calibrated_physics", r)
                for r in ("after_calibrated_physics", "at_calibrated_calibrated_physics")
            ]
            inputs += [r for r in sweeps if r.endswith("_calibrated_physics")]
        path = {role: f"sweeps/{role}/{EVAL_FILE}" for role in sweeps}
        args = [
            f"--inputs={flag_list(path[r] for r in inputs)}",
            f"--labels={flag_list(role_label(r) for r in inputs)}",
            f"--before={flag_list(path[b] for b, _ in pairs)}",
            f"--after={flag_list(path[a] for _, a in pairs)}",
            "--output_dir=report",
        ]
        self.add(
            REPORT,
            REPORT,
            "lerobot-phantom-report",
            tuple(args),
            "report",
            tuple(s.name for s in sweeps.values()),
        )

    def plan(self) -> list[Stage]:
        self.collect()
        self.clean_training()
        if self.cfg.select.enabled:
            self.selection()
        self.sweep("before", self.start_stage)
        self.lora("at", self.cfg.lora.rate, self.cfg.lora.attacks)
        self.lora("control", 0.0, self.cfg.lora.attacks)
        self.sweep("after", "train_at")
        self.sweep("control", "train_control")
        self.beyond()
        self.report()
        return self.stages


def plan(cfg: StudyConfig) -> list[Stage]:
    """Every stage of the study, in dependency order."""
    return Planner(cfg).plan()
