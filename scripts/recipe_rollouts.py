"""Clean rollouts of trained checkpoints on phantom_table with every gripper close logged (the recipe's failure analysis).

For each checkpoint: episodes on fixed seeds (episode ``i`` uses seed ``seed + i`` and task ``i % n_tasks``, so every
task gets an equal share and every checkpoint sees the same episodes), run in lock-step batches. Per episode it
records success, and for each transition of the gripper from open to closed: the TCP position, the position of the
object the task asks for, the offsets between them (xy distance, z) and whether something was grasped. Per step it
also records the scripted expert's action for the same state (privileged), so the policy's action error can be set
against the expert's. Readouts: ``--replan K`` executes the first K actions of each predicted chunk;
``--zero-noise`` starts the flow-matching integration from zeros instead of a Gaussian sample (a deterministic
readout). The flow noise is drawn from a seeded ``torch.Generator``.

    python scripts/recipe_rollouts.py CKPT_DIR [CKPT_DIR ...] --out FILE.json [--episodes 54] [--replan 5]
        [--zero-noise] [--suite goal] [--batch 9] [--seed 1000]

Writes one JSON file: per checkpoint the TSR with its 95 % Wilson interval, per-task successes, the grasp breakdown
(first close grasped the target / grasped nothing, median offsets) and every episode's record.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import numpy as np
import torch


def wilson(successes: int, n: int) -> list[float]:
    from scipy.stats import binomtest

    interval = binomtest(successes, n).proportion_ci(confidence_level=0.95, method="wilson")
    return [float(interval.low), float(interval.high)]


def load(checkpoint: Path):
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.policies.factory import get_policy_class, make_pre_post_processors

    from lerobot_phantom import register

    register()  # the plugin's processor steps (e.g. --mask_state's) that a checkpoint's preprocessor may name

    config = PreTrainedConfig.from_pretrained(checkpoint)
    policy = get_policy_class(config.type).from_pretrained(checkpoint)
    policy.eval()
    preprocessor, postprocessor = make_pre_post_processors(policy.config, pretrained_path=str(checkpoint))
    return policy, preprocessor, postprocessor


def run_batch(policy, preprocessor, postprocessor, envs, seeds, task_ids, replan, zero_noise, generator):
    from lerobot.envs.utils import preprocess_observation

    from lerobot_phantom.envs.experts import scripted_expert

    observations = [
        env.reset(seed=s, options={"task_id": t})[0] for env, s, t in zip(envs, seeds, task_ids, strict=True)
    ]
    experts = [scripted_expert(env) for env in envs]
    records = [
        {
            "seed": s,
            "task_id": t,
            "task": env.task,
            "success": False,
            "steps": 0,
            "closes": [],
            "action_err": [],
        }
        for env, s, t in zip(envs, seeds, task_ids, strict=True)
    ]
    done = [False] * len(envs)
    queue: list[np.ndarray] = []
    cfg = policy.config
    for step in range(envs[0].max_episode_steps):
        if not queue:
            stacked = {
                "pixels": {
                    cam: np.stack([o["pixels"][cam] for o in observations])
                    for cam in observations[0]["pixels"]
                },
                "agent_pos": np.stack([o["agent_pos"] for o in observations]),
            }
            batch = preprocess_observation(stacked)
            batch["task"] = [env.task_description for env in envs]
            batch = preprocessor(batch)
            shape = (len(envs), cfg.chunk_size, cfg.max_action_dim)
            noise = torch.zeros(shape) if zero_noise else torch.randn(shape, generator=generator)
            chunk = policy.predict_action_chunk(batch, noise=noise)
            chunk = torch.stack([postprocessor(chunk[:, k]) for k in range(chunk.shape[1])], dim=1)
            queue = [chunk[:, k].numpy() for k in range(min(replan, chunk.shape[1]))]
        actions = queue.pop(0)
        for i, env in enumerate(envs):
            if done[i]:
                continue
            expert_action = np.asarray(experts[i](observations[i]))
            action = np.clip(actions[i], -1.0, 1.0)
            was_closed = env.gripper_closed
            obs, _, terminated, truncated, info = env.step(action)
            record = records[i]
            record["action_err"].append(float(np.linalg.norm(action[:3] - expert_action[:3])))
            if env.gripper_closed and not was_closed:
                wanted = env.goals()[0][1] if env.held_object is None else env.held_object
                offset = env.position(wanted) - env.tcp
                record["closes"].append(
                    {
                        "step": step,
                        "tcp": [round(float(v), 4) for v in env.tcp],
                        "object": wanted,
                        "dxy_m": round(float(np.linalg.norm(offset[:2])), 4),
                        # positive: the TCP is above the object's centre
                        "dz_m": round(float(-offset[2]), 4),
                        "grasped": env.held_object,
                    }
                )
            observations[i] = obs
            record["steps"] = step + 1
            if terminated or truncated:
                done[i] = True
                record["success"] = bool(info["is_success"])
        if all(done):
            break
    return records


def summarise(records: list[dict]) -> dict:
    n = len(records)
    wins = sum(r["success"] for r in records)
    first = [r["closes"][0] for r in records if r["closes"]]
    hit = [c for c in first if c["grasped"] is not None]
    miss = [c for c in first if c["grasped"] is None]
    per_task: dict[str, list[int]] = {}
    for r in records:
        per_task.setdefault(r["task"], [0, 0])
        per_task[r["task"]][0] += int(r["success"])
        per_task[r["task"]][1] += 1

    def median(values):
        return round(statistics.median(values), 4) if values else None

    return {
        "episodes": n,
        "successes": wins,
        "tsr": wins / n,
        "wilson95": wilson(wins, n),
        "per_task": {k: {"successes": v[0], "episodes": v[1]} for k, v in per_task.items()},
        "grasp": {
            "episodes_with_a_close": len(first),
            "first_close_grasped": len(hit),
            "first_close_grasped_nothing": len(miss),
            "no_close_at_all": n - len(first),
            "median_dxy_m_miss": median([c["dxy_m"] for c in miss]),
            "median_dz_m_miss": median([c["dz_m"] for c in miss]),
            "median_dxy_m_hit": median([c["dxy_m"] for c in hit]),
            "median_dz_m_hit": median([c["dz_m"] for c in hit]),
            "max_closes_in_an_episode": max((len(r["closes"]) for r in records), default=0),
        },
        "median_action_err_vs_expert": median([e for r in records for e in r["action_err"]]),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+", type=Path)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--episodes", type=int, default=54)
    parser.add_argument("--batch", type=int, default=9)
    parser.add_argument(
        "--replan", type=int, default=0, help="actions executed per chunk (0: the policy's own)"
    )
    parser.add_argument("--zero-noise", action="store_true")
    parser.add_argument("--suite", default="goal")
    parser.add_argument("--seed", type=int, default=1000)
    parser.add_argument("--image-size", type=int, default=96)
    args = parser.parse_args()
    if args.out.exists():
        raise SystemExit(f"{args.out} exists; choose another --out")
    torch.set_num_threads(1)

    from lerobot_phantom.envs import SUITES
    from lerobot_phantom.envs.table_env import make_phantom_env

    n_tasks = len(SUITES[args.suite])
    envs = [make_phantom_env(args.suite, image_size=args.image_size) for _ in range(args.batch)]
    results = []
    for checkpoint in args.checkpoints:
        started = time.perf_counter()
        policy, preprocessor, postprocessor = load(checkpoint)
        replan = args.replan or policy.config.n_action_steps
        generator = torch.Generator().manual_seed(args.seed)
        records = []
        for first in range(0, args.episodes, args.batch):
            indices = range(first, min(first + args.batch, args.episodes))
            records += run_batch(
                policy,
                preprocessor,
                postprocessor,
                envs[: len(indices)],
                [args.seed + i for i in indices],
                [i % n_tasks for i in indices],
                replan,
                args.zero_noise,
                generator,
            )
        summary = summarise(records)
        summary.update(
            checkpoint=str(checkpoint),
            replan=replan,
            zero_noise=args.zero_noise,
            seconds=round(time.perf_counter() - started, 1),
            load_average=os.getloadavg(),
        )
        print(
            f"{checkpoint}: TSR {summary['successes']}/{summary['episodes']} = {summary['tsr']:.2f} "
            f"[{summary['wilson95'][0]:.2f}, {summary['wilson95'][1]:.2f}] grasp {summary['grasp']} "
            f"action_err {summary['median_action_err_vs_expert']} ({summary['seconds']} s)",
            flush=True,
        )
        results.append({**summary, "records": records})
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(results, indent=1))
    for env in envs:
        env.close()


if __name__ == "__main__":
    main()
