"""Benchmark lerobot-phantom-eval: episodes/s of attacked conditions against the clean control, in one run.

The rollouts are LeRobot's own loop on vectorised ``phantom_table`` envs (``--batch-size`` envs per vector env);
the policy is the scripted expert behind LeRobot's policy interface, which costs almost nothing and ignores the
images, so every condition runs the very same trajectories and the only extra work is the attack itself (the worst
case for the overhead: a neural policy makes the rollout slower and the attack's share smaller). Target: attack
overhead <= 5 % of rollout time.

Conditions alternate (clean, attack 1, ..., clean, attack 1, ...; ``--repeats`` rounds) and the best time of each is
kept, so load from other processes hits all alike. Prints the ratios and writes JSON (``--output``).

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
from lerobot.optim.optimizers import AdamConfig
from lerobot.policies.pretrained import PreTrainedPolicy
from tqdm import tqdm

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.envs import scripted_expert
from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig
from lerobot_phantom.eval.config import EvalPhantomConfig, PhantomEvalConfig
from lerobot_phantom.eval.eval import identity_processors, run_condition
from lerobot_phantom.eval.rollout import AttackStep, build_conditions
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS


@PreTrainedConfig.register_subclass("phantom_bench_expert")
@dataclass
class ExpertConfig(PreTrainedConfig):
    device: str | None = "cpu"

    @property
    def observation_delta_indices(self):
        return None

    @property
    def action_delta_indices(self):
        return None

    @property
    def reward_delta_indices(self):
        return None

    def get_optimizer_preset(self):
        return AdamConfig()

    def get_scheduler_preset(self):
        return None

    def validate_features(self) -> None:
        return None


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
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
    policy = ExpertPolicy(ExpertConfig(), vector_env)
    env_pre, env_post = compat.eval_env_processors(env_cfg, policy.config)
    processors = (env_pre, env_post, *identity_processors())
    conditions = build_conditions(cfg.phantom)
    steps = {c.key: AttackStep(c, cfg.phantom) for c in conditions}
    best = {c.key: float("inf") for c in conditions}
    steps = {}
    progress = tqdm(disable=True)
    try:
        with torch.no_grad():
            run_condition(vector_env, steps["clean"], cfg, policy, processors, None, progress)  # warm-up
            for _ in range(args.repeats):
                for condition in conditions:
                    start = time.perf_counter()
                    records = run_condition(
                        vector_env, steps[condition.key], cfg, policy, processors, None, progress
                    )
                    best[condition.key] = min(best[condition.key], time.perf_counter() - start)
                    steps[condition.key] = [r["steps"] for r in records]
    finally:
        compat.eval_close_envs(envs)

    clean = best["clean"]
    rows = []
    print(f"{'condition':<28} {'episodes/s':>10} {'time ratio':>10} {'overhead':>9}  same trajectories")
    for condition in conditions:
        seconds = best[condition.key]
        row = {
            "condition": condition.key,
            "seconds": seconds,
            "episodes_per_s": args.episodes / seconds,
            "time_ratio_vs_clean": seconds / clean,
            "overhead_pct": 100.0 * (seconds / clean - 1.0),
            "same_trajectories_as_clean": steps[condition.key] == steps["clean"],
        }
        rows.append(row)
        print(
            f"{condition.key:<28} {row['episodes_per_s']:10.2f} {row['time_ratio_vs_clean']:10.3f} "
            f"{row['overhead_pct']:8.1f}%  {row['same_trajectories_as_clean']}"
        )
    attacked = [r["overhead_pct"] for r in rows if r["condition"] != "clean"]
    summary = {
        "suite": args.suite,
        "batch_size": args.batch_size,
        "episodes": args.episodes,
        "repeats": args.repeats,
        "intensity": args.intensity,
        "mean_steps_per_episode": float(np.mean(steps["clean"])),
        "mean_overhead_pct": float(np.mean(attacked)),
        "max_overhead_pct": float(np.max(attacked)),
        "target_overhead_pct": 5.0,
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "torch": torch.__version__},
        "conditions": rows,
    }
    print(
        f"mean attack overhead {summary['mean_overhead_pct']:.1f}% (max {summary['max_overhead_pct']:.1f}%), target <= 5%"
    )
    with open(args.output, "w") as f:
        json.dump(summary, f, indent=2)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
