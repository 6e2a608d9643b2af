"""``lerobot-phantom-eval``: task success rate of a LeRobot policy, clean and under each attack x intensity.

    lerobot-phantom-eval --policy.path=outputs/train/run/checkpoints/last/pretrained_model \\
        --env.type=phantom_table --env.task=spatial --eval.n_episodes=50 --eval.batch_size=10 \\
        --phantom.attacks='[laser_blinding,voice_dos]' --phantom.intensities='[medium,strong]' --phantom.videos=2

Every condition (the clean control, then each attack at each intensity) runs the same env seeds
(``seed, seed+1, ...``, LeRobot's convention), so differences between conditions are paired. Results go to
``<output_dir>/eval.json`` (see ``evaluate``); ``lerobot-phantom-report`` turns one or more of them into tables.

In Python, ``evaluate(cfg, policy=...)`` evaluates an in-memory policy (anything with LeRobot's policy interface:
``reset()`` and ``select_action(batch)`` on the preprocessed batch); the CLI always loads ``--policy.path``.
With ``--dataset.*`` instead of ``--env.*`` it runs the offline mode (``lerobot_phantom.eval.offline``).
"""

import json
import time
from collections.abc import Callable
from contextlib import nullcontext
from dataclasses import asdict, dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import torch
from tqdm import tqdm

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.eval.config import PhantomEvalConfig
from lerobot_phantom.eval.loading import (
    identity_processors,
    load_policy,
    policy_metadata,
    ready_policy,
    versions,
    with_step,
)
from lerobot_phantom.eval.results import (
    EVAL_FILENAME,
    EVAL_FORMAT,
    per_task_summary,
    pooled_summary,
    summarize,
    write_eval,
)
from lerobot_phantom.eval.rollout import (
    AttackStep,
    Condition,
    EpisodeTasks,
    attack_steps,
    episode_outcomes,
)
from lerobot_phantom.transforms.base import derive_seed

# Re-exported for scripts that import them from here (they live in loading.py, shared with the offline mode).
__all__ = ["evaluate", "identity_processors", "load_policy", "run_condition", "with_step"]


@dataclass(frozen=True)
class TaskEnv:
    """One vector env of LeRobot's ``make_env`` output: ``{group: {env_id: env}}``."""

    suite: str
    env_id: int
    env: Any


def write_videos(
    videos_dir: Path, step: AttackStep, seeds: list[int], outcomes: list[dict], fps: int
) -> None:
    """The recorded frames of the first ``step.record`` envs of a batch, one mp4 per episode seed."""
    videos_dir.mkdir(parents=True, exist_ok=True)
    frames = np.stack(step.frames, axis=1)  # (envs, steps, H, W, 3)
    for i in range(step.record):
        compat.eval_write_video(
            videos_dir / f"episode_seed{seeds[i]}.mp4", frames[i, : outcomes[i]["steps"] + 1], fps
        )


def run_condition(
    env,
    step: AttackStep,
    cfg: PhantomEvalConfig,
    policy,
    processors: tuple,
    videos_dir: Path | None,
    progress: tqdm,
) -> list[dict[str, Any]]:
    """All episodes of one condition on one vectorised env; one record per episode (seed, task, success, ...)."""
    env_preprocessor, env_postprocessor, preprocessor, postprocessor = processors
    tasks = EpisodeTasks(env)
    # The task recorder runs before the attacker, so instruction attacks do not change the recorded instruction.
    attacked_env_preprocessor = with_step(env_preprocessor, tasks, step)
    rollout = compat.eval_rollout()
    n_episodes, num_envs = cfg.eval.n_episodes, env.num_envs
    records: list[dict[str, Any]] = []
    for batch_start in range(0, n_episodes, num_envs):
        # LeRobot's seed convention (eval_policy): episode i of a task runs env seed `seed + i`.
        seeds = list(range(cfg.seed + batch_start, cfg.seed + batch_start + num_envs))
        record = max(0, min(cfg.phantom.videos - batch_start, num_envs)) if videos_dir is not None else 0
        step.arm(seeds, record=record)
        tasks.arm()
        # Stochastic policies sample from the global RNGs: reseed identically in every condition so that policy
        # noise is paired too, and only the attack differs between conditions.
        compat.eval_seed_everything(derive_seed(cfg.seed, batch_start) % 2**32)
        data = rollout(
            env=env,
            policy=policy,
            env_preprocessor=attacked_env_preprocessor,
            env_postprocessor=env_postprocessor,
            preprocessor=preprocessor,
            postprocessor=postprocessor,
            seeds=seeds,
        )
        outcomes = episode_outcomes(data)
        used = min(num_envs, n_episodes - batch_start)
        records += [
            {"seed": seeds[i], **tasks.tasks[i], **outcomes[i], "attack_params": step.episode_params(i)}
            for i in range(used)
        ]
        if record:
            write_videos(videos_dir, step, seeds, outcomes, cfg.env.fps)
        progress.update(used)
    return records


def suite_name(group: str, env_cfg) -> str:
    """Name of a task group in the tables. LeRobot's ``make_env`` files single-id envs under the env type (e.g.
    ``{"pusht": {0: env}}``); the task (``PushT-v0``, a phantom_table suite) says more there."""
    return env_cfg.task if group == env_cfg.type and env_cfg.task else group


def result_row(condition: Condition, task_env: TaskEnv, records: list[dict[str, Any]]) -> dict[str, Any]:
    return {
        "condition": condition.key,
        "attack": condition.attack,
        "intensity": condition.intensity,
        "intensity_value": condition.intensity_value,
        "suite": task_env.suite,
        "task_id": task_env.env_id,
        **summarize(records),
        "per_episode": records,
    }


def run_all(
    cfg: PhantomEvalConfig,
    task_envs: list[TaskEnv],
    steps: list[AttackStep],
    policy,
    processors: tuple,
    done: dict[tuple, dict[str, Any]],
    on_row: Callable[[list[dict[str, Any]]], None],
) -> list[dict[str, Any]]:
    """Every condition on every env (same seeds everywhere); one result row per (env, condition). Rows already in
    ``done`` (keyed by ``row_key``, from an interrupted run) are kept, not re-run; ``on_row`` sees the rows so far
    after each new one."""
    device = torch.device(str(getattr(policy.config, "device", "cpu") or "cpu"))
    use_amp = bool(getattr(cfg.policy, "use_amp", False))
    results: list[dict[str, Any]] = []
    progress = tqdm(total=len(steps) * len(task_envs) * cfg.eval.n_episodes, desc="conditions x episodes")
    try:
        with torch.no_grad(), torch.autocast(device_type=device.type) if use_amp else nullcontext():
            for task_env, step in ((t, s) for t in task_envs for s in steps):
                key = (step.condition.key, task_env.suite, task_env.env_id)
                if key in done:
                    results.append(done[key])
                    progress.update(cfg.eval.n_episodes)
                    continue
                progress.set_postfix_str(f"{task_env.suite}/{task_env.env_id} {step.condition.key}")
                videos_dir = None
                if cfg.phantom.videos > 0:
                    name = f"{task_env.suite}_{task_env.env_id}"
                    videos_dir = Path(cfg.output_dir) / "videos" / step.condition.key.replace("@", "_") / name
                records = run_condition(task_env.env, step, cfg, policy, processors, videos_dir, progress)
                results.append(result_row(step.condition, task_env, records))
                on_row(results)
    finally:
        progress.close()
    return results


def row_key(row: dict[str, Any]) -> tuple:
    return (row["condition"], row["suite"], row["task_id"])


# Metadata that must be equal for an interrupted run's rows to be reused by --resume.
RESUME_MUST_MATCH = ("policy", "env", "n_episodes", "episode_seeds", "phantom")


def resumable_rows(cfg: PhantomEvalConfig, metadata: dict[str, Any]) -> dict[tuple, dict[str, Any]]:
    """Result rows of ``<output_dir>/eval.json`` that ``--resume=true`` may keep; {} without --resume or file."""
    path = Path(cfg.output_dir) / EVAL_FILENAME
    if not cfg.resume or not path.is_file():
        return {}
    with open(path) as f:
        previous = json.load(f)
    if previous.get("format") != EVAL_FORMAT or previous.get("mode") != "rollout":
        raise ValueError(f"--resume: {path} is not a rollout eval.json of format {EVAL_FORMAT}")
    differs = [k for k in RESUME_MUST_MATCH if previous["metadata"].get(k) != metadata[k]]
    if differs:
        raise ValueError(
            f"--resume: {path} was written with other settings ({', '.join(differs)} differ); "
            "evaluate into a fresh --output_dir or drop --resume"
        )
    return {row_key(row): row for row in previous["results"]}


def rollout_metadata(
    cfg: PhantomEvalConfig, policy, steps: list[AttackStep], task_envs: list[TaskEnv], started: float
) -> dict[str, Any]:
    return {
        "created": datetime.fromtimestamp(started, UTC).isoformat(timespec="seconds"),
        "duration_s": 0.0,
        "policy": policy_metadata(cfg, policy),
        "env": {"type": cfg.env.type, "task": cfg.env.task},
        "suites": list(dict.fromkeys(t.suite for t in task_envs)),
        "n_episodes": cfg.eval.n_episodes,
        "batch_size": cfg.eval.batch_size,
        "seed": cfg.seed,
        "episode_seeds": [cfg.seed + i for i in range(cfg.eval.n_episodes)],
        "conditions": [step.condition.key for step in steps],
        "attacks": {step.condition.key: repr(step.attack) for step in steps if step.attack is not None},
        "phantom": asdict(cfg.phantom),
        "calibrated_attacks": sorted({step.condition.attack for step in steps if step.calibrated}),
        "versions": versions(),
        "complete": False,
    }


def make_envs(cfg: PhantomEvalConfig):
    """LeRobot's ``make_env(cfg.env)``: ``{group: {env_id: vector_env}}``."""
    from lerobot.envs.factory import make_env

    return make_env(
        cfg.env,
        n_envs=cfg.eval.batch_size,
        use_async_envs=cfg.eval.use_async_envs,
        trust_remote_code=cfg.trust_remote_code,
    )


def rollout_report(metadata: dict[str, Any], results: list[dict[str, Any]], complete: bool) -> dict[str, Any]:
    """The eval.json content (``metadata.complete`` false while conditions are still missing)."""
    metadata["complete"] = complete
    return {
        "format": EVAL_FORMAT,
        "mode": "rollout",
        "metadata": metadata,
        "results": results,
        "summary": pooled_summary(results),
        "summary_per_task": per_task_summary(results),
    }


def evaluate(
    cfg: PhantomEvalConfig, policy=None, preprocessor=None, postprocessor=None, envs=None
) -> dict[str, Any]:
    """Run every condition, write ``<output_dir>/eval.json`` and return its content.

    ``policy``: an already-built policy (tests, notebooks); default = loaded from ``cfg.policy`` (``--policy.path``).
    Its ``preprocessor``/``postprocessor`` default to pass-through pipelines when a policy is given.
    ``envs``: ready ``{group: {task_id: vector_env}}`` (e.g. several suites at once); default = LeRobot's
    ``make_env(cfg.env)``. Envs passed in stay open (the caller owns them).
    """
    if cfg.dataset is not None:
        from lerobot_phantom.eval.offline import evaluate_offline

        return evaluate_offline(cfg, policy, preprocessor, postprocessor)
    if cfg.seed is None:
        raise ValueError("paired comparisons need fixed env seeds: pass --seed=<int> (default 1000)")
    started = time.time()
    steps = attack_steps(cfg.phantom)
    policy, preprocessor, postprocessor = ready_policy(cfg, policy, preprocessor, postprocessor)
    env_processors = compat.eval_env_processors(cfg.env, cfg.policy or policy.config)
    processors = (*env_processors, preprocessor, postprocessor)
    owns_envs = envs is None
    envs = make_envs(cfg) if owns_envs else envs
    task_envs = [
        TaskEnv(suite_name(group, cfg.env), env_id, env)
        for group, by_id in envs.items()
        for env_id, env in by_id.items()
    ]
    metadata = rollout_metadata(cfg, policy, steps, task_envs, started)

    def checkpoint(rows: list[dict[str, Any]]) -> None:
        # Rewritten after every condition, so that an interrupted sweep resumes per condition (--resume=true).
        metadata["duration_s"] = round(time.time() - started, 3)
        write_eval(cfg.output_dir, rollout_report(metadata, rows, complete=False))

    try:
        done = resumable_rows(cfg, metadata)
        results = run_all(cfg, task_envs, steps, policy, processors, done, checkpoint)
    finally:
        if owns_envs:
            compat.eval_close_envs(envs)
    metadata["duration_s"] = round(time.time() - started, 3)
    report = rollout_report(metadata, results, complete=True)
    write_eval(cfg.output_dir, report)
    return report


def format_summary(report: dict[str, Any]) -> str:
    """The pooled TSR per condition with its Wilson interval, then TSR (%) per task (columns) and condition."""
    lines = [f"{'condition':<28} {'TSR':>7}  95% Wilson CI"]
    for row in report["summary"]:
        low, high = row["ci95"]
        lines.append(
            f"{row['condition']:<28} {100 * row['tsr']:6.1f}%  [{100 * low:.1f}, {100 * high:.1f}]"
            f"  ({row['successes']}/{row['episodes']})"
        )
    per_task = report.get("summary_per_task") or []
    tasks = list(dict.fromkeys((r["suite"], r["task"]) for r in per_task))
    if len(tasks) > 1:
        lines += ["", "TSR (%) per task:"]
        lines += [f"  T{i}: {suite} / {task}" for i, (suite, task) in enumerate(tasks)]
        lines.append(f"{'condition':<28} " + " ".join(f"{f'T{i}':>6}" for i in range(len(tasks))))
        cell = {(r["condition"], r["suite"], r["task"]): r for r in per_task}
        for row in report["summary"]:
            values = [cell.get((row["condition"], *task)) for task in tasks]
            lines.append(
                f"{row['condition']:<28} "
                + " ".join("     -" if v is None else f"{100 * v['tsr']:6.1f}" for v in values)
            )
    return "\n".join(lines)


def eval_cli(cfg: PhantomEvalConfig) -> dict[str, Any]:
    report = evaluate(cfg)
    if report["mode"] == "rollout":
        print(format_summary(report))
    print(f"wrote {Path(cfg.output_dir) / EVAL_FILENAME}")
    return report


def main() -> None:
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    from lerobot.configs import parser
    from lerobot.utils.import_utils import register_third_party_plugins
    from lerobot.utils.utils import init_logging

    init_logging()
    register_third_party_plugins()
    parser.wrap()(eval_cli)()


if __name__ == "__main__":
    main()
