"""``lerobot-phantom-demo``: the whole robustness loop in miniature, on a CPU, with no data and no hub.

It runs the same commands a user would type, printing each one before running it:

1. ``lerobot-phantom-viz``        the attack gallery of the embedded sample image;
2. ``lerobot-phantom-eval``       a camera-driven reference policy (``phantom_servo``: colour segmentation of the
                                  front image + the instruction, no learning) on the built-in ``phantom_table``
                                  benchmark, clean and under all eight attacks at weak/medium/strong, paired seeds;
   ``lerobot-phantom-report``     the Table-3 style robustness table, TSR-vs-intensity curves and a summary;
3. the paper's defence loop (skip with ``--train=false``):
   ``lerobot-phantom-collect``    scripted-expert demonstrations (action noise on the executed motion);
   ``lerobot-phantom-make-vlm``   a local, weight-free SmolVLM directory (SmolVLA builds offline from it);
   ``lerobot-phantom-train``      stage 1, clean training of SmolVLA with the CPU recipe
                                  (``configs/smolvla_goal_cpu.json``, vision side trained) at a smaller scale;
                                  stage 2, adversarial LoRA fine-tuning from it with ``--phantom.rate``;
   ``lerobot-phantom-eval``       clean vs attacked task success before and after stage 2;
   ``lerobot-phantom-report``     the Table-5 style before/after table; the clean TSR is printed plainly.

Step 2 gives meaningful numbers in a minute or two. Step 3 is sized to fit the whole demo in about a quarter of an
hour on two cores, which is a fraction of the recipe's training (docs/recipe/README.md has the learning curve and
the TSR each scale reaches): it shows the pipeline and its outputs, and its clean TSR says how far a short run gets.
With ``--clean_policy=<pretrained_model dir>`` (a policy trained by the full recipe), or when a
``lerobot-phantom-study`` run left its clean policy in ``outputs/study`` (the checkpoint its selection stage chose),
step 3 skips clean training and runs the defence on that policy. ``--gallery_only`` stops after step 1.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path


@dataclass
class DemoConfig:
    out: str = "outputs/demo"
    # phantom_table suite: spatial | object | goal | long
    suite: str = "goal"
    # Step 3's training recipe (configs/smolvla_goal_cpu.json at a smaller scale; docs/recipe/ has its learning curve)
    episodes: int = 100
    action_noise: float = 0.3
    image_size: int = 96
    vlm_size: str = "small"
    clean_steps: int = 500
    phantom_steps: int = 50
    batch_size: int = 32
    # The recipe's 1e-4 keeps 2000-step runs from collapsing; a 500-step run learns faster at 3e-4 (docs/recipe,
    # step 500 on the same 50 validation episodes: 16% at 3e-4 (A2), 6% at 1e-4 (L))
    learning_rate: float = 3e-4
    chunk_size: int = 10
    # Replanning after every action: the chunk's later actions were fitted to noisy demonstrations (docs/recipe)
    n_action_steps: int = 1
    eval_episodes: int = 6
    # A trained clean policy (e.g. `lerobot-phantom-study`'s, or a run of configs/smolvla_goal_cpu.json): step 3
    # then evaluates and fine-tunes it instead of the policy trained here in a few minutes, which cannot solve the
    # tasks yet (docs/recipe/README.md)
    clean_policy: str | None = None
    # Without --clean_policy, use the clean policy of a `lerobot-phantom-study` run in outputs/study when present
    use_study_policy: bool = True
    # Episodes per condition for the reference policy's robustness table (step 2)
    servo_episodes: int = 10
    # Attacks evaluated (besides the clean control), as LeRobot lists: '[laser_blinding,voice_dos]'
    attacks: str = "[laser_blinding,light_projection,laser_color_strip,em_color_strip,em_truncation,ultrasound_blur,voice_dos,voice_spoofing]"
    # Levels of the robustness table (step 2) and of the before/after comparison (step 3)
    intensities: str = "[weak,medium,strong]"
    train_intensities: str = "[strong]"
    # Run step 3 (collect, clean training, adversarial LoRA, before/after evaluation)
    train: bool = True
    phantom_rate: float = 0.3
    lora_rank: int = 8
    seed: int = 0
    gallery_only: bool = False
    # Delete an existing --out first (it is otherwise refused, so no earlier run is lost)
    overwrite: bool = False


def _script(name: str) -> list[str]:
    """The console script ``name`` of this installation (falls back to ``python -m module``)."""
    modules = {
        "lerobot-phantom-viz": "lerobot_phantom.viz",
        "lerobot-phantom-collect": "lerobot_phantom.envs.collect",
        "lerobot-phantom-make-vlm": "lerobot_phantom.train.make_vlm",
        "lerobot-phantom-train": "lerobot_phantom.train.train",
        "lerobot-phantom-eval": "lerobot_phantom.eval.eval",
        "lerobot-phantom-report": "lerobot_phantom.eval.report",
    }
    executable = shutil.which(name)
    return [executable] if executable else [sys.executable, "-m", modules[name]]


def run(name: str, *args: str, log: Path) -> None:
    command = [*_script(name), *args]
    shown = " ".join([name, *(shlex.quote(a) for a in args)])
    print(f"\n$ {shown}", flush=True)
    # One torch thread per process: on two shared cores torch's default two threads made a training step several
    # times slower (issue 11; scripts/bench_train.py); a user's own OMP_NUM_THREADS wins.
    env = {"OMP_NUM_THREADS": "1", **os.environ, "HF_HUB_OFFLINE": "1"}
    started = time.time()
    with open(log, "a") as sink:
        sink.write(f"\n$ {shown}\n")
        sink.flush()
        result = subprocess.run(command, stdout=sink, stderr=subprocess.STDOUT, env=env, check=False)
    if result.returncode != 0:
        raise RuntimeError(f"{name} failed (exit {result.returncode}); its output is in {log}")
    print(f"  done in {time.time() - started:.0f} s", flush=True)


@dataclass
class _Run:
    """What every stage needs: the config, the output directory, the log and the outputs collected so far."""

    cfg: DemoConfig
    out: Path
    log: Path
    outputs: dict[str, Path]

    def run(self, name: str, *args: str) -> None:
        run(name, *args, log=self.log)


def demo(cfg: DemoConfig) -> dict[str, Path]:
    """Run the demo's stages in order; returns the paths of everything it wrote."""
    demo_run = _start(cfg)
    _gallery(demo_run)
    if cfg.gallery_only:
        return demo_run.outputs
    _servo_robustness(demo_run)
    if not cfg.train:
        return demo_run.outputs
    dataset = _collect(demo_run)
    clean_policy = _trained_policy(cfg)
    trained_here = clean_policy is None
    if trained_here:
        clean_policy = _train_clean(demo_run, dataset)
    phantom_policy = _train_adversarial(demo_run, dataset, clean_policy)
    _before_after(demo_run, clean_policy, phantom_policy, trained_here)
    return demo_run.outputs


# Where `lerobot-phantom-study` (default --output_dir) leaves its runs, relative to the working directory.
STUDY_DIR = Path("outputs/study")


def _trained_policy(cfg: DemoConfig) -> Path | None:
    """--clean_policy, else the study's clean policy when a study has run here (the checkpoint its selection stage
    chose on validation seeds, else the last one), else None (train one)."""
    from lerobot_phantom.study.stages import CLEAN_RUN, PRETRAINED, SELECTED_RUN

    if cfg.clean_policy is not None:
        return Path(cfg.clean_policy)
    if not cfg.use_study_policy:
        return None
    for policy in (STUDY_DIR / SELECTED_RUN / PRETRAINED, STUDY_DIR / CLEAN_RUN / PRETRAINED):
        if (policy / "config.json").exists():
            print(f"\nusing the clean policy trained by lerobot-phantom-study: {policy}", flush=True)
            return policy
    return None


def _start(cfg: DemoConfig) -> _Run:
    from lerobot_phantom.envs import SUITE_NAMES
    from lerobot_phantom.train.make_vlm import VLM_SIZES

    if cfg.suite not in SUITE_NAMES:
        raise ValueError(f"unknown --suite {cfg.suite!r}; valid: {', '.join(SUITE_NAMES)}")
    if cfg.vlm_size not in VLM_SIZES:
        raise ValueError(f"unknown --vlm_size {cfg.vlm_size!r}; valid: {', '.join(VLM_SIZES)}")
    if cfg.clean_policy is not None and not (Path(cfg.clean_policy) / "config.json").exists():
        raise FileNotFoundError(
            f"--clean_policy {cfg.clean_policy} has no config.json; give a pretrained_model directory"
        )
    out = Path(cfg.out)
    if out.exists():
        if not cfg.overwrite:
            raise FileExistsError(
                f"{out} exists; pass --overwrite=true to replace it or choose another --out"
            )
        shutil.rmtree(out)
    out.mkdir(parents=True)
    log = out / "demo.log"
    return _Run(cfg, out, log, {"gallery": out / "attacks.png", "log": log})


def _gallery(demo_run: _Run) -> None:
    demo_run.run("lerobot-phantom-viz", f"--out={demo_run.outputs['gallery']}", f"--seed={demo_run.cfg.seed}")


def _servo_robustness(demo_run: _Run) -> None:
    """Step 2: the camera-driven reference policy, clean and under every attack and level."""
    from lerobot_phantom.eval.servo_policy import save_servo_policy

    cfg, out = demo_run.cfg, demo_run.out
    servo_policy = save_servo_policy(out / "servo_policy", image_size=cfg.image_size)
    print(f"\nsaved the camera-driven reference policy to {servo_policy}", flush=True)
    servo_eval, servo_report = out / "eval_servo", out / "report_servo"
    demo_run.run(
        "lerobot-phantom-eval",
        f"--policy.path={servo_policy}",
        *_env_flags(cfg),
        f"--eval.n_episodes={cfg.servo_episodes}",
        f"--eval.batch_size={min(cfg.servo_episodes, 5)}",
        f"--seed={1000 + cfg.seed}",
        f"--phantom.attacks={cfg.attacks}",
        f"--phantom.intensities={cfg.intensities}",
        f"--output_dir={servo_eval}",
    )
    demo_run.run(
        "lerobot-phantom-report",
        f"--inputs=[{servo_eval / 'eval.json'}]",
        "--labels=[phantom_servo]",
        f"--output_dir={servo_report}",
    )
    demo_run.outputs.update(
        servo_policy=servo_policy, eval_servo=servo_eval / "eval.json", report_servo=servo_report
    )
    _print_summary(servo_report)


def _collect(demo_run: _Run) -> dict[str, str]:
    """Scripted-expert demonstrations; returns the ``--dataset.*`` flags that point at them."""
    cfg = demo_run.cfg
    dataset = demo_run.out / "dataset"
    repo_id = f"local/phantom_demo_{cfg.suite}"
    demo_run.run(
        "lerobot-phantom-collect",
        f"--suite={cfg.suite}",
        f"--episodes={cfg.episodes}",
        f"--repo_id={repo_id}",
        f"--root={dataset}",
        f"--image_size={cfg.image_size}",
        f"--action_noise={cfg.action_noise}",
        f"--seed={cfg.seed}",
        "--progress=false",
    )
    demo_run.outputs["dataset"] = dataset
    return {"repo_id": repo_id, "root": str(dataset)}


def _common_train_flags(cfg: DemoConfig, dataset: dict[str, str]) -> list[str]:
    return [
        f"--dataset.repo_id={dataset['repo_id']}",
        f"--dataset.root={dataset['root']}",
        f"--batch_size={cfg.batch_size}",
        "--num_workers=0",
        "--eval_freq=0",
        "--wandb.enable=false",
        f"--seed={cfg.seed}",
        f"--phantom.seed={cfg.seed}",
    ]


def recipe_policy_flags(cfg: DemoConfig, vlm: Path) -> list[str]:
    """The clean-training policy flags of the CPU recipe (configs/smolvla_goal_cpu.json) at the demo's scale."""
    from lerobot_phantom.train.make_vlm import VLM_SIZES

    vlm_image_size = VLM_SIZES[cfg.vlm_size]["image_size"]
    return [
        "--policy.type=smolvla",
        f"--policy.vlm_model_name={vlm}",
        "--policy.load_vlm_weights=false",
        # LeRobot's defaults (true, true) would keep the weight-free VLM at its random initialisation.
        "--policy.freeze_vision_encoder=false",
        "--policy.train_expert_only=false",
        f"--policy.resize_imgs_with_padding=[{vlm_image_size},{vlm_image_size}]",
        f"--policy.chunk_size={cfg.chunk_size}",
        f"--policy.n_action_steps={cfg.n_action_steps}",
        f"--policy.optimizer_lr={cfg.learning_rate}",
        # A constant learning rate after the warm-up (decay_lr = peak)
        f"--policy.scheduler_decay_lr={cfg.learning_rate}",
        "--policy.device=cpu",
        "--policy.push_to_hub=false",
    ]


def _train_clean(demo_run: _Run, dataset: dict[str, str]) -> Path:
    """Stage 1: a weight-free SmolVLM backbone, then clean training of SmolVLA on it (vision side trained)."""
    from lerobot_phantom.envs import SUITES

    cfg, out = demo_run.cfg, demo_run.out
    vlm = out / "vlm"
    instructions = ",".join(task["language"] for task in SUITES[cfg.suite])
    demo_run.run(
        "lerobot-phantom-make-vlm", f"--out={vlm}", f"--size={cfg.vlm_size}", f"--tasks=[{instructions}]"
    )
    clean_dir = out / "train_clean"
    demo_run.run(
        "lerobot-phantom-train",
        *recipe_policy_flags(cfg, vlm),
        f"--steps={cfg.clean_steps}",
        f"--save_freq={cfg.clean_steps}",
        f"--log_freq={max(1, cfg.clean_steps // 4)}",
        f"--output_dir={clean_dir}",
        "--phantom.rate=0",
        *_common_train_flags(cfg, dataset),
    )
    return clean_dir / "checkpoints" / "last" / "pretrained_model"


def _train_adversarial(demo_run: _Run, dataset: dict[str, str], clean_policy: Path) -> Path:
    """Stage 2: adversarial LoRA fine-tuning from the clean policy at ``--phantom_rate``."""
    from lerobot_phantom.train import SMOLVLA_VISION_LORA_TARGETS

    cfg = demo_run.cfg
    phantom_dir = demo_run.out / "train_phantom"
    demo_run.run(
        "lerobot-phantom-train",
        f"--policy.path={clean_policy}",
        "--policy.push_to_hub=false",
        f"--peft.r={cfg.lora_rank}",
        f"--peft.target_modules={SMOLVLA_VISION_LORA_TARGETS}",
        f"--steps={cfg.phantom_steps}",
        f"--save_freq={cfg.phantom_steps}",
        f"--log_freq={max(1, cfg.phantom_steps // 4)}",
        f"--output_dir={phantom_dir}",
        f"--phantom.rate={cfg.phantom_rate}",
        *_common_train_flags(cfg, dataset),
    )
    return phantom_dir / "checkpoints" / "last" / "pretrained_model"


def _before_after(demo_run: _Run, clean_policy: Path, phantom_policy: Path, trained_here: bool) -> None:
    """Clean vs attacked task success before and after stage 2, and the Table-5 style report."""
    cfg, out = demo_run.cfg, demo_run.out
    evals = {}
    for label, policy in (("before", clean_policy), ("after", phantom_policy)):
        evals[label] = out / f"eval_{label}"
        demo_run.run(
            "lerobot-phantom-eval",
            f"--policy.path={policy}",
            *_env_flags(cfg),
            f"--eval.n_episodes={cfg.eval_episodes}",
            f"--eval.batch_size={min(cfg.eval_episodes, 6)}",
            f"--seed={1000 + cfg.seed}",
            f"--phantom.attacks={cfg.attacks}",
            f"--phantom.intensities={cfg.train_intensities}",
            f"--output_dir={evals[label]}",
        )
    report = out / "report"
    demo_run.run(
        "lerobot-phantom-report",
        f"--before=[{evals['before'] / 'eval.json'}]",
        f"--after=[{evals['after'] / 'eval.json'}]",
        f"--output_dir={report}",
    )
    demo_run.outputs.update(
        clean_policy=clean_policy,
        phantom_policy=phantom_policy,
        eval_before=evals["before"] / "eval.json",
        eval_after=evals["after"] / "eval.json",
        report=report,
    )
    _print_summary(report)
    _print_clean_tsr(evals["before"] / "eval.json", clean_policy, cfg.clean_steps if trained_here else None)


def _print_clean_tsr(eval_json: Path, clean_policy: Path, steps_trained_here: int | None) -> None:
    """State plainly what the clean policy achieved and what a demo-sized run can show."""
    summary = json.loads(eval_json.read_text())["summary"]
    clean = next(row for row in summary if row["condition"] == "clean")
    low, high = clean["ci95"]
    source = (
        f"the trained policy {clean_policy}"
        if steps_trained_here is None
        else f"the policy trained here ({steps_trained_here} steps)"
    )
    print(
        f"\nClean TSR of {source}: {clean['successes']}/{clean['episodes']} = {100 * clean['tsr']:.0f} % "
        f"(95 % Wilson interval {100 * low:.0f}-{100 * high:.0f} %).",
        flush=True,
    )
    if steps_trained_here is not None:
        print(
            "A few minutes of CPU training is far from the recipe's full run (docs/recipe/README.md has its learning "
            "curve): expect a low clean TSR, so the before/after table shows the pipeline, not the defence. Pass "
            "--clean_policy=<a trained pretrained_model directory> to run step 3 on a policy that solves tasks.",
            flush=True,
        )


def _env_flags(cfg: DemoConfig) -> list[str]:
    return [
        "--env.type=phantom_table",
        f"--env.task={cfg.suite}",
        f"--env.observation_height={cfg.image_size}",
        f"--env.observation_width={cfg.image_size}",
    ]


def _print_summary(report_dir: Path) -> None:
    for name in ("robustness.md", "before_after.md", "summary.md"):
        path = report_dir / name
        if path.exists():
            print("\n" + path.read_text(), flush=True)


def main() -> None:
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    import draccus

    cfg = draccus.parse(config_class=DemoConfig)
    outputs = demo(cfg)
    print("\nOutputs:\n" + json.dumps({k: str(v) for k, v in outputs.items()}, indent=2))


if __name__ == "__main__":
    main()
