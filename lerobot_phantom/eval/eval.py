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
import platform
import time
from contextlib import nullcontext
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import torch
from tqdm import tqdm

import lerobot_phantom
from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.eval.config import PhantomEvalConfig
from lerobot_phantom.eval.results import EVAL_FILENAME, EVAL_FORMAT, pooled_summary, summarize
from lerobot_phantom.eval.rollout import AttackStep, build_conditions, episode_outcomes
from lerobot_phantom.transforms.base import derive_seed


def identity_processors():
    """Pass-through pre/post processors for an in-memory policy that needs no normalisation."""
    from lerobot.processor import PolicyProcessorPipeline
    from lerobot.processor.converters import policy_action_to_transition, transition_to_policy_action

    return (
        PolicyProcessorPipeline(steps=[]),
        PolicyProcessorPipeline(
            steps=[], to_transition=policy_action_to_transition, to_output=transition_to_policy_action
        ),
    )


def load_policy(cfg: PhantomEvalConfig, ds_meta=None):
    """Policy and its pre/post processors from ``--policy.path``, exactly as ``lerobot-eval`` builds them
    (``ds_meta``: a dataset's metadata instead of the env config, for the offline mode)."""
    from lerobot.policies.factory import make_policy, make_pre_post_processors

    if cfg.policy is None:
        raise ValueError(
            "no policy to evaluate: pass --policy.path=<checkpoint dir> (or policy= to evaluate())"
        )
    # A dataset's metadata (offline mode) or the env config tells make_policy the features.
    source = {"ds_meta": ds_meta} if ds_meta is not None else {"env_cfg": cfg.env}
    policy = make_policy(cfg=cfg.policy, rename_map=cfg.rename_map, **source)
    preprocessor, postprocessor = make_pre_post_processors(
        policy_cfg=cfg.policy,
        pretrained_path=cfg.policy.pretrained_path,
        preprocessor_overrides={
            "device_processor": {"device": str(policy.config.device)},
            "rename_observations_processor": {"rename_map": cfg.rename_map},
        },
    )
    return policy, preprocessor, postprocessor


def with_step(pipeline, step):
    """A copy of ``pipeline`` with ``step`` appended (same converters), leaving the original untouched."""
    return type(pipeline)(
        steps=[*pipeline.steps, step],
        name=pipeline.name,
        to_transition=pipeline.to_transition,
        to_output=pipeline.to_output,
    )


def versions() -> dict[str, str]:
    return {
        "lerobot": compat.lerobot_version(),
        "lerobot_phantom": lerobot_phantom.__version__,
        "torch": torch.__version__,
        "python": platform.python_version(),
    }


def policy_metadata(cfg: PhantomEvalConfig, policy) -> dict[str, Any]:
    path = (
        None if cfg.policy is None or cfg.policy.pretrained_path is None else str(cfg.policy.pretrained_path)
    )
    config = getattr(policy, "config", None)
    return {"path": path, "type": getattr(config, "type", None) or type(policy).__name__}


def run_condition(
    env,
    step: AttackStep,
    cfg: PhantomEvalConfig,
    policy,
    processors: tuple,
    videos_dir: Path | None,
    progress: tqdm,
) -> list[dict[str, Any]]:
    """All episodes of one condition on one vectorised task env; one record per episode (seed, success, ...)."""
    env_preprocessor, env_postprocessor, preprocessor, postprocessor = processors
    attacked_env_preprocessor = with_step(env_preprocessor, step)
    rollout = compat.eval_rollout()
    n_episodes, num_envs = cfg.eval.n_episodes, env.num_envs
    records: list[dict[str, Any]] = []
    for batch_start in range(0, n_episodes, num_envs):
        # LeRobot's seed convention (eval_policy): episode i of a task runs env seed `seed + i`.
        seeds = list(range(cfg.seed + batch_start, cfg.seed + batch_start + num_envs))
        record = max(0, min(cfg.phantom.videos - batch_start, num_envs)) if videos_dir is not None else 0
        step.arm(seeds, record=record)
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
        for i in range(used):
            records.append({"seed": seeds[i], **outcomes[i], "attack_params": step.episode_params(i)})
        if record:
            videos_dir.mkdir(parents=True, exist_ok=True)
            frames = np.stack(step.frames, axis=1)  # (envs, steps, H, W, 3)
            for i in range(record):
                compat.eval_write_video(
                    videos_dir / f"episode_seed{seeds[i]}.mp4",
                    frames[i, : outcomes[i]["steps"] + 1],
                    cfg.env.fps,
                )
        progress.update(used)
    return records


def suite_name(group: str, env_cfg) -> str:
    """Name of a task group in the tables. LeRobot's ``make_env`` files single-id envs under the env type (e.g.
    ``{"pusht": {0: env}}``); the task (``PushT-v0``, a phantom_table suite) says more there."""
    return env_cfg.task if group == env_cfg.type and env_cfg.task else group


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
    from lerobot.envs.factory import make_env

    started = time.time()
    conditions = build_conditions(cfg.phantom)
    # Every attack is built up front, so that a bad name or calibration fails before any rollout.
    steps = [AttackStep(condition, cfg.phantom) for condition in conditions]
    if policy is None:
        policy, preprocessor, postprocessor = load_policy(cfg)
    elif preprocessor is None or postprocessor is None:
        preprocessor, postprocessor = identity_processors()
    policy.eval()
    env_preprocessor, env_postprocessor = compat.eval_env_processors(cfg.env, cfg.policy or policy.config)
    processors = (env_preprocessor, env_postprocessor, preprocessor, postprocessor)

    output_dir = Path(cfg.output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    owns_envs = envs is None
    if owns_envs:
        envs = make_env(
            cfg.env,
            n_envs=cfg.eval.batch_size,
            use_async_envs=cfg.eval.use_async_envs,
            trust_remote_code=cfg.trust_remote_code,
        )
    tasks = [
        (suite_name(group, cfg.env), task_id, env)
        for group, by_id in envs.items()
        for task_id, env in by_id.items()
    ]
    results: list[dict[str, Any]] = []
    device = torch.device(str(getattr(policy.config, "device", "cpu") or "cpu"))
    use_amp = bool(getattr(cfg.policy, "use_amp", False))
    progress = tqdm(total=len(conditions) * len(tasks) * cfg.eval.n_episodes, desc="conditions x episodes")
    try:
        with torch.no_grad(), torch.autocast(device_type=device.type) if use_amp else nullcontext():
            for suite, task_id, env in tasks:
                for condition, step in zip(conditions, steps, strict=True):
                    progress.set_postfix_str(f"{suite}/{task_id} {condition.key}")
                    videos_dir = None
                    if cfg.phantom.videos > 0:
                        videos_dir = (
                            output_dir / "videos" / condition.key.replace("@", "_") / f"{suite}_{task_id}"
                        )
                    records = run_condition(env, step, cfg, policy, processors, videos_dir, progress)
                    results.append(
                        {
                            "condition": condition.key,
                            "attack": condition.attack,
                            "intensity": condition.intensity,
                            "intensity_value": condition.intensity_value,
                            "suite": suite,
                            "task_id": task_id,
                            **summarize(records),
                            "per_episode": records,
                        }
                    )
    finally:
        progress.close()
        if owns_envs:
            compat.eval_close_envs(envs)

    report = {
        "format": EVAL_FORMAT,
        "mode": "rollout",
        "metadata": {
            "created": datetime.now(UTC).isoformat(timespec="seconds"),
            "duration_s": round(time.time() - started, 3),
            "policy": policy_metadata(cfg, policy),
            "env": {"type": cfg.env.type, "task": cfg.env.task},
            "suites": list(dict.fromkeys(suite for suite, _, _ in tasks)),
            "n_episodes": cfg.eval.n_episodes,
            "batch_size": cfg.eval.batch_size,
            "seed": cfg.seed,
            "episode_seeds": [cfg.seed + i for i in range(cfg.eval.n_episodes)],
            "conditions": [c.key for c in conditions],
            "attacks": {step.condition.key: repr(step.attack) for step in steps if step.attack is not None},
            "phantom": asdict(cfg.phantom),
            "versions": versions(),
        },
        "results": results,
        "summary": pooled_summary(results),
    }
    with open(output_dir / EVAL_FILENAME, "w") as f:
        json.dump(report, f, indent=2)
    return report


def format_summary(report: dict[str, Any]) -> str:
    lines = [f"{'condition':<28} {'TSR':>7}  95% CI"]
    for row in report["summary"]:
        low, high = row["ci95"]
        lines.append(
            f"{row['condition']:<28} {100 * row['tsr']:6.1f}%  [{100 * low:.1f}, {100 * high:.1f}]"
            f"  ({row['successes']}/{row['episodes']})"
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
