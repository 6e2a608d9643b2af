"""lerobot-phantom-collect: record scripted-expert demonstrations as a LeRobotDataset v3.

    lerobot-phantom-collect --suite goal --episodes 100 --repo-id local/phantom_goal --root DIR \\
        [--video] [--seed 0] [--overwrite] [--task-id K] [--image-size 96] [--action-noise 0.3] \\
        [--grasp-miss-rate 0.5]

Episodes cycle round-robin over the selected (suite, task) pairs, so ``--episodes`` is the total count and every
task gets an equal share; ``--suite all`` cycles over every task of every suite (interleaving the suites) into one
multi-task dataset. Only successful expert episodes are kept: a failed attempt is discarded and retried with the next seed (the number of
discarded attempts is reported). Episode seeds are drawn from ``numpy.random.default_rng(seed)``, so a given
``--seed`` always produces the same dataset. Features: ``observation.images.front`` / ``observation.images.wrist``
(images, or AV1 videos with ``--video``), ``observation.state`` (TCP xyz + finger opening), ``action``
(normalised [dx, dy, dz, grip]); the task string is the instruction.

``--grasp-miss-rate P`` makes a share P of the episodes miss their first grasp on purpose: the executed approach aims
``--grasp-miss-min-m``..``--grasp-miss-max-m`` off the object in xy (beyond the env's grasp tolerance by default),
closes on nothing, and the expert re-opens and grasps again. The recorded action stays the unshifted expert's at every
step, so the data holds what relative action noise cannot give: frames near the object but centimetres off, labelled
with the correction, and the recovery from a close on nothing.
"""

from __future__ import annotations

import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from lerobot_phantom._cli import normalize_argv as normalize_cli_argv
from lerobot_phantom.envs.interface import ACTION_NAMES, CAMERAS, CONTROL_HZ, GRASP_XY_TOL, STATE_NAMES
from lerobot_phantom.envs.suites import SUITE_NAMES, SUITES

ALL_SUITES = "all"


@dataclass
class CollectConfig:
    suite: str = "goal"  # spatial | object | goal | long | all
    episodes: int = 100  # total number of (successful) episodes, round-robin over the suite's tasks
    repo_id: str | None = None  # default: local/phantom_<suite>
    root: str | None = None  # dataset directory; default: LeRobot's HF_LEROBOT_HOME/<repo_id>
    video: bool = False  # store camera streams as videos instead of PNG images
    seed: int = 0
    overwrite: bool = False  # delete an existing dataset at root first
    task_id: int | None = None  # only this task of the suite (not with --suite all)
    action_noise: float = (
        0.0  # relative std of noise on the executed (not the recorded) motion; 0.3 is a good start
    )
    grasp_miss_rate: float = 0.0  # share of episodes whose first grasp is aimed off the object on purpose
    # xy distance of the missed grasp from the object, drawn uniformly between the two
    grasp_miss_min_m: float = GRASP_XY_TOL + 0.002
    grasp_miss_max_m: float = 0.04
    image_size: int = 96
    vcodec: str = "libsvtav1"
    image_writer_threads: int = 2  # PNG writing overlaps the simulation; 2 threads suit a 2-core machine
    max_failed_attempts: int = 50  # give up if the expert fails this often (it should essentially never fail)
    progress: bool = True


@dataclass
class CollectResult:
    root: Path
    repo_id: str
    episodes: int
    frames: int
    failed_attempts: int
    seconds: float

    @property
    def frames_per_second(self) -> float:
        return self.frames / self.seconds if self.seconds > 0 else float("nan")


def _task_plan(cfg: CollectConfig) -> list[tuple[str, int]]:
    if cfg.suite == ALL_SUITES:
        if cfg.task_id is not None:
            raise ValueError(
                "--task-id selects a task within one suite; it cannot be combined with --suite all"
            )
        # Interleave suites so that even a short collection covers all four.
        most_tasks = max(len(SUITES[suite]) for suite in SUITE_NAMES)
        return [(suite, k) for k in range(most_tasks) for suite in SUITE_NAMES if k < len(SUITES[suite])]
    if cfg.suite not in SUITE_NAMES:
        raise ValueError(f"unknown suite {cfg.suite!r}; valid: {', '.join(SUITE_NAMES)} or {ALL_SUITES!r}")
    if cfg.task_id is not None:
        if not 0 <= cfg.task_id < len(SUITES[cfg.suite]):
            raise ValueError(
                f"task_id {cfg.task_id} out of range for suite {cfg.suite!r}: valid 0..{len(SUITES[cfg.suite]) - 1}"
            )
        return [(cfg.suite, cfg.task_id)]
    return [(cfg.suite, k) for k in range(len(SUITES[cfg.suite]))]


def dataset_features(image_size: int, video: bool) -> dict:
    image = {
        "dtype": "video" if video else "image",
        "shape": (image_size, image_size, 3),
        "names": ["height", "width", "channels"],
    }
    return {
        **{f"observation.images.{cam}": dict(image) for cam in CAMERAS},
        "observation.state": {"dtype": "float32", "shape": (len(STATE_NAMES),), "names": list(STATE_NAMES)},
        "action": {"dtype": "float32", "shape": (len(ACTION_NAMES),), "names": list(ACTION_NAMES)},
    }


def grasp_miss_offset(rng: np.random.Generator, rate: float, min_m: float, max_m: float) -> np.ndarray | None:
    """The xy offset of an episode's deliberately missed first grasp, or None (probability ``1 - rate``)."""
    if rate <= 0.0 or rng.random() >= rate:
        return None
    angle = rng.uniform(0.0, 2.0 * np.pi)
    return rng.uniform(min_m, max_m) * np.array([np.cos(angle), np.sin(angle)])


def _record_episode(
    env,
    expert,
    seed: int,
    task_id: int,
    dataset,
    action_noise: float = 0.0,
    miss_offset: np.ndarray | None = None,
) -> tuple[bool, int]:
    """Roll the expert out once, adding every frame to the dataset's episode buffer; returns (success, frames).

    With ``action_noise`` the executed motion is perturbed (each axis scaled by ``1 + N(0, action_noise)``) while
    the recorded action stays the expert's, so the data shows how to recover from small drifts (DART-style).
    With ``miss_offset`` (xy, metres) the executed motion aims the first grasp that far off the object until the
    gripper closes; the recorded action stays the unshifted expert's.
    """
    obs, info = env.reset(seed=seed, options={"task_id": task_id})
    noise_rng = np.random.default_rng(seed)
    language = env.task_description
    for step in range(env.max_episode_steps):
        action = np.asarray(expert(obs), dtype=np.float32)
        if env.gripper_closed:
            # the aimed-off close happened: from here on the expert executes its own actions
            miss_offset = None
        if miss_offset is None:
            executed = action.copy()
        else:
            executed = np.asarray(expert(obs, aim_offset=miss_offset), dtype=np.float32)
        if action_noise > 0:
            # Relative noise: large during transit, vanishing as the expert homes in, so it still converges.
            executed[:3] = np.clip(
                executed[:3] * (1.0 + noise_rng.normal(0.0, action_noise, size=3)), -1.0, 1.0
            )
        dataset.add_frame(
            {
                **{f"observation.images.{cam}": obs["pixels"][cam] for cam in CAMERAS},
                "observation.state": obs["agent_pos"],
                "action": action,
                "task": language,
            }
        )
        obs, _, terminated, truncated, info = env.step(executed)
        if terminated or truncated:
            return bool(info["is_success"]), step + 1
    return False, env.max_episode_steps


def collect(cfg: CollectConfig) -> CollectResult:
    """Collect ``cfg.episodes`` successful expert episodes into a new LeRobotDataset v3 at ``cfg.root``."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset
    from lerobot.utils.constants import HF_LEROBOT_HOME

    from lerobot_phantom.envs.experts import scripted_expert
    from lerobot_phantom.envs.table_env import make_phantom_env

    _check_config(cfg)
    plan = _task_plan(cfg)
    repo_id = cfg.repo_id or f"local/phantom_{cfg.suite}"
    root = Path(cfg.root) if cfg.root is not None else HF_LEROBOT_HOME / repo_id
    if root.exists():
        if not cfg.overwrite:
            raise FileExistsError(
                f"{root} already exists; pass --overwrite to replace it (or choose another --root)"
            )
        shutil.rmtree(root)

    dataset = LeRobotDataset.create(
        repo_id=repo_id,
        fps=CONTROL_HZ,
        features=dataset_features(cfg.image_size, cfg.video),
        root=root,
        robot_type="phantom_mocap_gripper",
        use_videos=cfg.video,
        image_writer_threads=cfg.image_writer_threads,
        vcodec=cfg.vcodec,
    )
    envs = {}
    rng = np.random.default_rng(cfg.seed)
    frames = failed = 0
    start = time.perf_counter()
    try:
        with tqdm(
            total=cfg.episodes, desc=f"collect {cfg.suite}", unit="ep", disable=not cfg.progress
        ) as bar:
            for episode in range(cfg.episodes):
                suite, task_id = plan[episode % len(plan)]
                if suite not in envs:
                    env = make_phantom_env(suite, image_size=cfg.image_size)
                    envs[suite] = (env, scripted_expert(env))
                env, expert = envs[suite]
                length, failed = _record_until_success(
                    env, expert, rng, cfg, dataset, suite=suite, task_id=task_id, failed=failed
                )
                dataset.save_episode(parallel_encoding=False)
                frames += length
                bar.update(1)
                bar.set_postfix(frames=frames, failed=failed)
    finally:
        dataset.stop_image_writer()
        dataset.finalize()
        for env, _ in envs.values():
            env.close()
    return CollectResult(root, repo_id, cfg.episodes, frames, failed, time.perf_counter() - start)


def _check_config(cfg: CollectConfig) -> None:
    if cfg.episodes < 1:
        raise ValueError("--episodes must be at least 1")
    if not 0.0 <= cfg.action_noise <= 1.0:
        raise ValueError(f"--action-noise must be in [0, 1] (relative std), got {cfg.action_noise}")
    if not 0.0 <= cfg.grasp_miss_rate <= 1.0:
        raise ValueError(
            f"--grasp-miss-rate must be in [0, 1] (a share of episodes), got {cfg.grasp_miss_rate}"
        )
    if not 0.0 < cfg.grasp_miss_min_m <= cfg.grasp_miss_max_m:
        raise ValueError(
            "--grasp-miss-min-m and --grasp-miss-max-m must satisfy 0 < min <= max (metres), got "
            f"{cfg.grasp_miss_min_m} and {cfg.grasp_miss_max_m}"
        )


def _record_until_success(
    env,
    expert,
    rng: np.random.Generator,
    cfg: CollectConfig,
    dataset,
    *,
    suite: str,
    task_id: int,
    failed: int,
) -> tuple[int, int]:
    """Record episodes of ``task_id`` (fresh episode seeds from ``rng``) until the expert succeeds, dropping the
    failed ones from the dataset's buffer: (length of the successful episode, failed attempts so far)."""
    while True:
        episode_seed = int(rng.integers(2**31 - 1))
        # its own stream, so that a dataset without misses is the one collected before they existed
        miss_offset = grasp_miss_offset(
            np.random.default_rng([episode_seed, 1]),
            cfg.grasp_miss_rate,
            cfg.grasp_miss_min_m,
            cfg.grasp_miss_max_m,
        )
        success, length = _record_episode(
            env, expert, episode_seed, task_id, dataset, cfg.action_noise, miss_offset
        )
        if success:
            return length, failed
        dataset.clear_episode_buffer()
        failed += 1
        if failed > cfg.max_failed_attempts:
            raise RuntimeError(
                f"the scripted expert failed {failed} times (last: suite {suite}, task {task_id})"
            )


_BARE_FLAGS = ("video", "overwrite", "progress")


def normalize_argv(argv: list[str]) -> list[str]:
    return normalize_cli_argv(argv, _BARE_FLAGS)


def main(argv: list[str] | None = None) -> None:
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    import draccus

    cfg = draccus.parse(CollectConfig, args=normalize_argv(sys.argv[1:] if argv is None else list(argv)))
    try:
        result = collect(cfg)
    except (FileExistsError, ValueError) as err:  # user errors: one clear line instead of a traceback
        raise SystemExit(f"lerobot-phantom-collect: {err}") from err
    print(
        f"wrote {result.root} ({result.episodes} episodes, {result.frames} frames, "
        f"{result.failed_attempts} failed attempts discarded, {result.frames_per_second:.1f} frames/s)"
    )
