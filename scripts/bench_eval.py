"""Benchmark lerobot-phantom-eval: episodes/s of attacked conditions against the clean control, in one run.

The rollouts are LeRobot's own loop on vectorised ``phantom_table`` envs (``--batch-size`` envs per vector env);
``--policy expert`` (default) is the scripted expert behind LeRobot's policy interface, which costs almost nothing
and ignores the images, so every condition runs the very same trajectories and the only extra work is the attack
itself: the worst case for the overhead. ``--policy act`` is a small randomly initialised LeRobot ACT (ResNet-18
backbone on both cameras), a more realistic per-step cost; its episodes run to the step limit in every condition.
Target: attack overhead <= 5 % of rollout time.

Two measures, both from this one run: the wall-time ratio of each attacked condition to the clean control
(conditions alternate over ``--repeats`` rounds and the best time of each is kept), and the attack's share of its
own rollouts: time spent inside the attack step / rollout time, measured on the same rollouts, hence insensitive
to load from other processes (which makes the wall-time ratio noisy on a shared machine). Prints both and writes
JSON (``--output``).

    MUJOCO_GL=egl python scripts/bench_eval.py --suite goal --batch-size 4 --episodes 8 --repeats 2
"""

import argparse
import json
import os
import platform
import tempfile
import time
from dataclasses import dataclass

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np
import torch
from lerobot.configs.default import EvalConfig
from lerobot.configs.policies import PreTrainedConfig
from lerobot.envs.factory import make_env
from lerobot.policies.pretrained import PreTrainedPolicy
from tqdm import tqdm

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.envs import scripted_expert
from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig
from lerobot_phantom.eval.config import EvalPhantomConfig, PhantomEvalConfig
from lerobot_phantom.eval.eval import identity_processors, run_condition
from lerobot_phantom.eval.rollout import AttackStep, build_conditions
from lerobot_phantom.eval.servo_policy import NonLearnedPolicyConfig
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS


@PreTrainedConfig.register_subclass("phantom_bench_expert")
@dataclass
class ExpertConfig(NonLearnedPolicyConfig):
    """The scripted expert behind LeRobot's policy interface (nothing to configure)."""


class ExpertPolicy(PreTrainedPolicy):
    """phantom_table's scripted expert (reads the sim state) as a LeRobot policy for one vector env."""

    config_class = ExpertConfig
    name = "phantom_bench_expert"

    def __init__(self, config, vector_env):
        super().__init__(config)
        self.experts = [scripted_expert(env) for env in vector_env.envs]

    def get_optim_params(self):
        return self.parameters()

    def reset(self):
        return None

    def forward(self, batch):
        raise NotImplementedError

    def predict_action_chunk(self, batch, **kwargs):
        return self.select_action(batch)[:, None]

    def select_action(self, batch, **kwargs):
        return torch.as_tensor(np.stack([expert() for expert in self.experts]))


class TimedAttackStep(AttackStep):
    """AttackStep that accumulates the wall time spent in it (the whole attack: parameter draws and application)."""

    seconds = 0.0

    def __call__(self, transition):
        start = time.perf_counter()
        try:
            return super().__call__(transition)
        finally:
            self.seconds += time.perf_counter() - start


def small_act(env_cfg):
    """A small ACT with random weights (no download) and its processors, as LeRobot's factories build them."""
    from lerobot.policies.act.configuration_act import ACTConfig
    from lerobot.policies.factory import make_policy, make_pre_post_processors

    config = ACTConfig(
        pretrained_backbone_weights=None,
        dim_model=64,
        dim_feedforward=128,
        n_heads=2,
        n_encoder_layers=1,
        n_decoder_layers=1,
        chunk_size=10,
        n_action_steps=10,
        use_vae=False,
        device="cpu",
    )
    policy = make_policy(config, env_cfg=env_cfg)
    return policy, make_pre_post_processors(config, dataset_stats=None)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", choices=("expert", "act"), default="expert")
    parser.add_argument("--suite", default="goal")
    parser.add_argument("--batch-size", type=int, default=4)
    parser.add_argument("--episodes", type=int, default=8)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--intensity", default="strong")
    parser.add_argument("--attacks", default=",".join(CAMERA_ATTACKS))
    parser.add_argument("--output", default="bench_eval.json")
    args = parser.parse_args()

    torch.set_num_threads(1)
    env_cfg = PhantomTableEnvConfig(task=args.suite)
    envs = make_env(env_cfg, n_envs=args.batch_size)
    (vector_env,) = (env for group in envs.values() for env in group.values())
    cfg = PhantomEvalConfig(
        env=env_cfg,
        eval=EvalConfig(n_episodes=args.episodes, batch_size=args.batch_size),
        output_dir=tempfile.mkdtemp(),
        phantom=EvalPhantomConfig(attacks=args.attacks.split(","), intensities=[args.intensity]),
    )
    if args.policy == "expert":
        policy = ExpertPolicy(ExpertConfig(), vector_env)
        policy_processors = identity_processors()
    else:
        policy, policy_processors = small_act(env_cfg)
    env_pre, env_post = compat.eval_env_processors(env_cfg, policy.config)
    processors = (env_pre, env_post, *policy_processors)
    conditions = build_conditions(cfg.phantom)
    steps = {c.key: TimedAttackStep(c, cfg.phantom) for c in conditions}
    best = {c.key: float("inf") for c in conditions}
    total = {c.key: 0.0 for c in conditions}
    lengths = {}
    progress = tqdm(disable=True)
    try:
        with torch.no_grad():
            run_condition(vector_env, steps["clean"], cfg, policy, processors, None, progress)  # warm-up
            steps["clean"].seconds = 0.0
            for _ in range(args.repeats):
                for condition in conditions:
                    start = time.perf_counter()
                    records = run_condition(
                        vector_env, steps[condition.key], cfg, policy, processors, None, progress
                    )
                    elapsed = time.perf_counter() - start
                    best[condition.key] = min(best[condition.key], elapsed)
                    total[condition.key] += elapsed
                    lengths[condition.key] = [r["steps"] for r in records]
    finally:
        compat.eval_close_envs(envs)

    clean = best["clean"]
    rows = []
    print(f"{'condition':<28} {'episodes/s':>10} {'wall ratio':>10} {'attack share':>12}  same trajectories")
    for condition in conditions:
        seconds = best[condition.key]
        row = {
            "condition": condition.key,
            "best_seconds": seconds,
            "episodes_per_s": args.episodes / seconds,
            "wall_time_ratio_vs_clean": seconds / clean,
            "attack_share_pct": 100.0 * steps[condition.key].seconds / total[condition.key],
            "same_trajectories_as_clean": lengths[condition.key] == lengths["clean"],
        }
        rows.append(row)
        print(
            f"{condition.key:<28} {row['episodes_per_s']:10.2f} {row['wall_time_ratio_vs_clean']:10.3f} "
            f"{row['attack_share_pct']:11.2f}%  {row['same_trajectories_as_clean']}"
        )
    attacked = [r for r in rows if r["condition"] != "clean"]
    summary = {
        "policy": args.policy,
        "suite": args.suite,
        "batch_size": args.batch_size,
        "episodes": args.episodes,
        "repeats": args.repeats,
        "intensity": args.intensity,
        "mean_steps_per_episode": float(np.mean(lengths["clean"])),
        "mean_attack_share_pct": float(np.mean([r["attack_share_pct"] for r in attacked])),
        "max_attack_share_pct": float(np.max([r["attack_share_pct"] for r in attacked])),
        "mean_wall_time_ratio": float(np.mean([r["wall_time_ratio_vs_clean"] for r in attacked])),
        "target_overhead_pct": 5.0,
        "machine": {
            "python": platform.python_version(),
            "cpus": os.cpu_count(),
            "torch": torch.__version__,
            "load_avg_1min": os.getloadavg()[0],
        },
        "conditions": rows,
    }
    print(
        f"attack share of rollout time: mean {summary['mean_attack_share_pct']:.2f}%, "
        f"max {summary['max_attack_share_pct']:.2f}% (target <= 5%); "
        f"mean wall-time ratio attacked/clean {summary['mean_wall_time_ratio']:.3f} "
        f"(load average {summary['machine']['load_avg_1min']:.1f} on {os.cpu_count()} cpus)"
    )
    with open(args.output, "w") as f:
        json.dump(summary, f, indent=2)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
