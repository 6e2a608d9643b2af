"""LeRobot ``EnvConfig`` for the phantom tabletop, registered as type ``phantom_table`` on import.

    lerobot-eval --env.type=phantom_table --env.task=goal [--env.task_id=3] \\
        --env.discover_packages_path=lerobot_phantom --policy.path=...

``--env.task`` selects the suite (spatial, object, goal, long). ``--env.task_id`` pins one task of the suite;
left unset, every reset draws one of the suite's tasks from the env's seeded RNG, so a stock ``lerobot-eval`` run
covers the whole suite (reported under the single group ``phantom_table``, like other single-id envs).
``make_phantom_vector_envs`` builds LIBERO-style ``{suite: {task_id: vector_env}}`` mappings for per-task
evaluation. Stock ``make_env`` builds the envs with ``gym.make`` on ``lerobot_phantom/PhantomTable-v0``; the id is
registered without wrappers so that lerobot-eval's ``add_envs_task`` sees ``task_description`` and passes the
instruction to the policy as ``task`` (keep ``disable_env_checker=True``, the default, for the same reason).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig
from lerobot.utils.constants import ACTION, OBS_IMAGES, OBS_STATE

from lerobot_phantom.envs import GYM_ID, SUITE_NAMES, SUITES
from lerobot_phantom.envs.interface import ACTION_DIM, CAMERAS, CONTROL_HZ, OBS_TYPES, STATE_DIM

ENV_TYPE = "phantom_table"


@EnvConfig.register_subclass(ENV_TYPE)
@dataclass
class PhantomTableEnvConfig(EnvConfig):
    task: str = "goal"
    task_id: int | None = None
    fps: int = CONTROL_HZ
    episode_length: int | None = None  # None: the suite's default (80 steps, 160 for long)
    obs_type: str = "pixels_agent_pos"
    render_mode: str = "rgb_array"
    observation_height: int = 96
    observation_width: int = 96
    render_size: int | None = (
        None  # side of the frames lerobot-eval saves as videos; None: the observation size
    )
    features: dict[str, PolicyFeature] = field(
        default_factory=lambda: {ACTION: PolicyFeature(type=FeatureType.ACTION, shape=(ACTION_DIM,))}
    )
    features_map: dict[str, str] = field(
        default_factory=lambda: {
            ACTION: ACTION,
            "agent_pos": OBS_STATE,
            **{f"pixels/{cam}": f"{OBS_IMAGES}.{cam}" for cam in CAMERAS},
        }
    )

    def __post_init__(self):
        if self.task not in SUITE_NAMES:
            raise ValueError(
                f"unknown phantom_table task (suite) {self.task!r}; valid: {', '.join(SUITE_NAMES)}"
            )
        if self.task_id is not None and not 0 <= self.task_id < len(SUITES[self.task]):
            raise ValueError(
                f"task_id {self.task_id} out of range for suite {self.task!r}: "
                f"valid 0..{len(SUITES[self.task]) - 1}"
            )
        if not self.disable_env_checker:
            raise ValueError(
                "phantom_table needs disable_env_checker=True: gymnasium's checker wrapper hides the env's "
                "task_description from lerobot-eval, and policies would silently receive empty instructions"
            )
        if self.obs_type not in OBS_TYPES:
            raise ValueError(f"unknown obs_type {self.obs_type!r}; valid: {', '.join(OBS_TYPES)}")
        image_shape = (self.observation_height, self.observation_width, 3)
        for cam in CAMERAS:
            self.features[f"pixels/{cam}"] = PolicyFeature(type=FeatureType.VISUAL, shape=image_shape)
        if self.obs_type == "pixels_agent_pos":
            self.features["agent_pos"] = PolicyFeature(type=FeatureType.STATE, shape=(STATE_DIM,))

    @property
    def package_name(self) -> str:
        return "lerobot_phantom.envs"

    @property
    def gym_id(self) -> str:
        return GYM_ID

    @property
    def gym_kwargs(self) -> dict[str, Any]:
        return {
            "suite": self.task,
            "task_id": self.task_id,
            "image_size": (self.observation_height, self.observation_width),
            "obs_type": self.obs_type,
            "render_mode": self.render_mode,
            "episode_length": self.episode_length,
            "render_size": self.render_size,
        }


def make_phantom_vector_envs(
    cfg: PhantomTableEnvConfig,
    n_envs: int = 1,
    use_async_envs: bool = False,
    suites: str | None = None,
) -> dict[str, dict[int, gym.vector.VectorEnv]]:
    """LIBERO-style ``{suite: {task_id: vector_env}}``: one vector env of ``n_envs`` copies per task.

    ``suites`` is a comma-separated list or ``all`` (default: ``cfg.task``); ``cfg.task_id`` restricts each suite
    to that one task.
    """
    if n_envs < 1:
        raise ValueError("n_envs must be at least 1")
    names = SUITE_NAMES if suites == "all" else tuple(s.strip() for s in (suites or cfg.task).split(","))
    unknown = [s for s in names if s not in SUITE_NAMES]
    if unknown:
        raise ValueError(f"unknown suites {unknown}; valid: {', '.join(SUITE_NAMES)} or 'all'")
    env_cls = gym.vector.AsyncVectorEnv if use_async_envs else gym.vector.SyncVectorEnv
    out: dict[str, dict[int, gym.vector.VectorEnv]] = {}
    for suite in names:
        task_ids = [cfg.task_id] if cfg.task_id is not None else list(range(len(SUITES[suite])))
        out[suite] = {}
        for task_id in task_ids:
            kwargs = cfg.gym_kwargs | {"suite": suite, "task_id": task_id}

            def make_one(kwargs=kwargs):
                return gym.make(cfg.gym_id, disable_env_checker=cfg.disable_env_checker, **kwargs)

            out[suite][task_id] = env_cls(
                [make_one for _ in range(n_envs)], autoreset_mode=gym.vector.AutoresetMode.SAME_STEP
            )
    return out
