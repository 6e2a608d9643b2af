"""``lerobot-phantom-demo``: the whole robustness loop in miniature, on a CPU, with no data and no hub.

It runs the same commands a user would type, printing each one before running it:

1. ``lerobot-phantom-viz``        the attack gallery of the embedded sample image;
2. ``lerobot-phantom-eval``       a camera-driven reference policy (``phantom_servo``: colour segmentation of the
                                  front image + the instruction, no learning) on the built-in ``phantom_table``
                                  benchmark, clean and under all eight attacks at weak/medium/strong, paired seeds;
   ``lerobot-phantom-report``     the Table-3 style robustness table, TSR-vs-intensity curves and a summary;
3. the paper's defence loop (skip with ``--train=false``):
   ``lerobot-phantom-collect``    scripted-expert demonstrations;
   ``lerobot-phantom-make-vlm``   a local, weight-free SmolVLM directory (SmolVLA builds offline from it);
   ``lerobot-phantom-train``      stage 1, clean training of a tiny SmolVLA; stage 2, adversarial LoRA fine-tuning
                                  from it with ``--phantom.rate``;
   ``lerobot-phantom-eval``       clean vs attacked task success before and after stage 2;
   ``lerobot-phantom-report``     the Table-5 style before/after table.

Step 2 gives meaningful numbers in a minute or two. Step 3 finishes in minutes on two cores, so its policy is far
too small and briefly trained to solve the tasks: it shows the pipeline and its outputs. Scale ``--episodes``,
``--clean_steps``, ``--phantom_steps`` and ``--eval_episodes`` (and use ``configs/smolvla_lora_phantom.json`` on a
GPU) for meaningful numbers there. ``--gallery_only`` stops after step 1.
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
    episodes: int = 8
    image_size: int = 96
    clean_steps: int = 60
    phantom_steps: int = 30
    batch_size: int = 4
    eval_episodes: int = 4
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
    env = {**os.environ, "HF_HUB_OFFLINE": "1"}
    started = time.time()
    with open(log, "a") as sink:
        sink.write(f"\n$ {shown}\n")
        sink.flush()
        result = subprocess.run(command, stdout=sink, stderr=subprocess.STDOUT, env=env, check=False)
    if result.returncode != 0:
        raise RuntimeError(f"{name} failed (exit {result.returncode}); its output is in {log}")
    print(f"  done in {time.time() - started:.0f} s", flush=True)


def demo(cfg: DemoConfig) -> dict[str, Path]:
    from lerobot_phantom.envs import SUITE_NAMES

    if cfg.suite not in SUITE_NAMES:
        raise ValueError(f"unknown --suite {cfg.suite!r}; valid: {', '.join(SUITE_NAMES)}")
    out = Path(cfg.out)
    if out.exists():
        if not cfg.overwrite:
            raise FileExistsError(
                f"{out} exists; pass --overwrite=true to replace it or choose another --out"
            )
        shutil.rmtree(out)
    out.mkdir(parents=True)
    log = out / "demo.log"
    outputs = {"gallery": out / "attacks.png", "log": log}

    run("lerobot-phantom-viz", f"--out={outputs['gallery']}", f"--seed={cfg.seed}", log=log)
    if cfg.gallery_only:
        return outputs

    from lerobot_phantom.eval.servo_policy import save_servo_policy

    servo_policy = save_servo_policy(out / "servo_policy", image_size=cfg.image_size)
    print(f"\nsaved the camera-driven reference policy to {servo_policy}", flush=True)
    servo_eval, servo_report = out / "eval_servo", out / "report_servo"
    run(
        "lerobot-phantom-eval",
        f"--policy.path={servo_policy}",
        *_env_flags(cfg),
        f"--eval.n_episodes={cfg.servo_episodes}",
        f"--eval.batch_size={min(cfg.servo_episodes, 5)}",
        f"--seed={1000 + cfg.seed}",
        f"--phantom.attacks={cfg.attacks}",
        f"--phantom.intensities={cfg.intensities}",
        f"--output_dir={servo_eval}",
        log=log,
    )
    run(
        "lerobot-phantom-report",
        f"--inputs=[{servo_eval / 'eval.json'}]",
        "--labels=[phantom_servo]",
        f"--output_dir={servo_report}",
        log=log,
    )
    outputs.update(servo_policy=servo_policy, eval_servo=servo_eval / "eval.json", report_servo=servo_report)
    _print_summary(servo_report)
    if not cfg.train:
        return outputs

    dataset, vlm = out / "dataset", out / "vlm"
    repo_id = f"local/phantom_demo_{cfg.suite}"
    run(
        "lerobot-phantom-collect",
        f"--suite={cfg.suite}",
        f"--episodes={cfg.episodes}",
        f"--repo_id={repo_id}",
        f"--root={dataset}",
        f"--image_size={cfg.image_size}",
        f"--seed={cfg.seed}",
        "--progress=false",
        log=log,
    )
    from lerobot_phantom.envs import SUITES
    from lerobot_phantom.train import SMOLVLA_VISION_LORA_TARGETS
    from lerobot_phantom.train.make_vlm import VLM_SIZES

    instructions = ",".join(task["language"] for task in SUITES[cfg.suite])
    run("lerobot-phantom-make-vlm", f"--out={vlm}", "--size=tiny", f"--tasks=[{instructions}]", log=log)
    vlm_image_size = VLM_SIZES["tiny"]["image_size"]

    common = [
        f"--dataset.repo_id={repo_id}",
        f"--dataset.root={dataset}",
        f"--batch_size={cfg.batch_size}",
        "--num_workers=0",
        "--eval_freq=0",
        "--wandb.enable=false",
        f"--seed={cfg.seed}",
        f"--phantom.seed={cfg.seed}",
    ]
    clean_dir, phantom_dir = out / "train_clean", out / "train_phantom"
    run(
        "lerobot-phantom-train",
        "--policy.type=smolvla",
        f"--policy.vlm_model_name={vlm}",
        "--policy.load_vlm_weights=false",
        f"--policy.resize_imgs_with_padding=[{vlm_image_size},{vlm_image_size}]",
        "--policy.chunk_size=4",
        "--policy.n_action_steps=4",
        "--policy.num_steps=4",
        "--policy.device=cpu",
        "--policy.push_to_hub=false",
        f"--steps={cfg.clean_steps}",
        f"--save_freq={cfg.clean_steps}",
        f"--log_freq={max(1, cfg.clean_steps // 4)}",
        f"--output_dir={clean_dir}",
        "--phantom.rate=0",
        *common,
        log=log,
    )
    clean_policy = clean_dir / "checkpoints" / "last" / "pretrained_model"
    run(
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
        *common,
        log=log,
    )
    phantom_policy = phantom_dir / "checkpoints" / "last" / "pretrained_model"

    evals = {}
    for label, policy in (("before", clean_policy), ("after", phantom_policy)):
        evals[label] = out / f"eval_{label}"
        run(
            "lerobot-phantom-eval",
            f"--policy.path={policy}",
            *_env_flags(cfg),
            f"--eval.n_episodes={cfg.eval_episodes}",
            f"--eval.batch_size={min(cfg.eval_episodes, 4)}",
            f"--seed={1000 + cfg.seed}",
            f"--phantom.attacks={cfg.attacks}",
            f"--phantom.intensities={cfg.train_intensities}",
            f"--output_dir={evals[label]}",
            log=log,
        )
    report = out / "report"
    run(
        "lerobot-phantom-report",
        f"--before=[{evals['before'] / 'eval.json'}]",
        f"--after=[{evals['after'] / 'eval.json'}]",
        f"--output_dir={report}",
        log=log,
    )
    outputs.update(
        dataset=dataset,
        clean_policy=clean_policy,
        phantom_policy=phantom_policy,
        eval_before=evals["before"] / "eval.json",
        eval_after=evals["after"] / "eval.json",
        report=report,
    )
    _print_summary(report)
    return outputs


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
