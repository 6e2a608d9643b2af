"""Benchmark the phantom tabletop: env steps/s (both cameras rendered) on one core, scripted-expert success per
suite, and dataset collection frames/s. Prints a table and writes JSON.

    python scripts/bench_envs.py [--out outputs/bench_envs.json] [--expert_seeds 100] [--steps 500]
        [--collect_episodes 10]
"""

import json
import os
import platform
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

# One core: pin every thread pool before numpy / torch / mujoco are imported.
for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "LP_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
os.environ.setdefault("HF_HUB_OFFLINE", "1")

import draccus  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402

from lerobot_phantom.envs import SUITE_NAMES, SUITES, make_phantom_env, scripted_expert  # noqa: E402
from lerobot_phantom.envs.collect import CollectConfig, collect  # noqa: E402


@dataclass
class BenchEnvsConfig:
    out: Path = Path("outputs/bench_envs.json")
    image_size: int = 96
    steps: int = 500  # random-action env steps per suite for the throughput figure
    expert_seeds: int = 100  # expert episodes per suite (tasks round-robin, seed = episode index)
    collect_episodes: int = 10  # per collection mode (images, video), goal suite
    suites: list[str] = field(default_factory=lambda: list(SUITE_NAMES))


def bench_steps(suite: str, steps: int, image_size: int) -> dict:
    env = make_phantom_env(suite, image_size=image_size)
    rng = np.random.default_rng(0)
    env.reset(seed=0)
    env.step(np.zeros(4, dtype=np.float32))  # renderer creation outside the timed loop
    start = time.perf_counter()
    for _ in range(steps):
        obs, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, size=4).astype(np.float32))
        if terminated or truncated:
            env.reset()
    elapsed = time.perf_counter() - start
    env.close()
    assert obs["pixels"]["front"].shape == (image_size, image_size, 3)
    return {"steps": steps, "seconds": elapsed, "steps_per_s": steps / elapsed}


def bench_expert(suite: str, seeds: int, image_size: int) -> dict:
    env = make_phantom_env(suite, image_size=image_size)
    expert = scripted_expert(env)
    n_tasks = len(SUITES[suite])
    successes, lengths, failures = 0, [], []
    start = time.perf_counter()
    for seed in range(seeds):
        obs, _ = env.reset(seed=seed, options={"task_id": seed % n_tasks})
        length = 0
        while True:
            obs, _, terminated, truncated, info = env.step(expert(obs))
            length += 1
            if terminated or truncated:
                break
        lengths.append(length)
        if info["is_success"]:
            successes += 1
        else:
            failures.append({"seed": seed, "task": info["task"]})
    elapsed = time.perf_counter() - start
    env.close()
    return {
        "episodes": seeds,
        "success_rate": successes / seeds,
        "mean_length": float(np.mean(lengths)),
        "max_length": int(np.max(lengths)),
        "failures": failures,
        "seconds": elapsed,
    }


def bench_collect(episodes: int, video: bool, image_size: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        cfg = CollectConfig(
            suite="goal",
            episodes=episodes,
            repo_id="local/bench_envs",
            root=str(Path(tmp) / "ds"),
            video=video,
            image_size=image_size,
            progress=False,
        )
        result = collect(cfg)
    return {
        "episodes": result.episodes,
        "frames": result.frames,
        "seconds": result.seconds,
        "frames_per_s": result.frames_per_second,
    }


@draccus.wrap()
def main(cfg: BenchEnvsConfig) -> dict:
    torch.set_num_threads(1)
    result: dict = {
        "machine": {"python": platform.python_version(), "cpu_count": os.cpu_count(), "threads": 1},
        "mujoco_gl": os.environ.get("MUJOCO_GL"),
        "image_size": cfg.image_size,
        "env_steps": {},
        "expert": {},
        "collect": {},
    }
    for suite in cfg.suites:
        result["env_steps"][suite] = bench_steps(suite, cfg.steps, cfg.image_size)
        print(f"env steps/s  {suite:8s} {result['env_steps'][suite]['steps_per_s']:8.1f}", flush=True)
    for suite in cfg.suites:
        result["expert"][suite] = bench_expert(suite, cfg.expert_seeds, cfg.image_size)
        r = result["expert"][suite]
        print(
            f"expert       {suite:8s} {100 * r['success_rate']:6.1f}% of {r['episodes']} (mean length "
            f"{r['mean_length']:.1f})",
            flush=True,
        )
    for mode, video in (("images", False), ("video", True)):
        result["collect"][mode] = bench_collect(cfg.collect_episodes, video, cfg.image_size)
        print(f"collect      {mode:8s} {result['collect'][mode]['frames_per_s']:8.1f} frames/s", flush=True)

    print("\n| suite | env steps/s (1 core, 2 cams 96x96) | expert success (seeds) | mean episode length |")
    print("|---|---|---|---|")
    for suite in cfg.suites:
        steps, expert = result["env_steps"][suite], result["expert"][suite]
        print(
            f"| {suite} | {steps['steps_per_s']:.0f} | {100 * expert['success_rate']:.0f}% ({expert['episodes']}) "
            f"| {expert['mean_length']:.1f} |"
        )
    for mode in ("images", "video"):
        print(f"collection ({mode}): {result['collect'][mode]['frames_per_s']:.0f} frames/s")
    cfg.out.parent.mkdir(parents=True, exist_ok=True)
    cfg.out.write_text(json.dumps(result, indent=2))
    print(f"wrote {cfg.out}")
    return result


if __name__ == "__main__":
    main()
