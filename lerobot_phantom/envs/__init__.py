"""Built-in MuJoCo tabletop benchmark: four LIBERO-like suites, scripted experts, dataset collection.

Stable API (importing this package is cheap: mujoco is only imported when an env is built):

- ``make_phantom_env(suite, task_id=None, image_size=96, seed=None, obs_type="pixels_agent_pos",
  render_mode="rgb_array", episode_length=None, render_size=None) -> PhantomTableEnv`` (a gymnasium.Env).
  ``task_id=None`` draws a task of the suite at every reset from the env's seeded RNG; an int pins one task.
- ``SUITES``: suite name -> list of task dicts ``{"name", "language", "goals"}`` (see suites.py);
  ``SUITE_NAMES = ("spatial", "object", "goal", "long")``.
- ``scripted_expert(env) -> callable(obs) -> action`` (reads privileged sim state; ``ScriptedExpert`` class);
  ``record_expert_episode(env, seed, task_id=None)`` -> {"language", "success", "frames", "actions"}.
- ``collect(CollectConfig)`` / the ``lerobot-phantom-collect`` CLI (collect.py) write LeRobotDataset v3.
- ``PhantomTableEnvConfig`` (lerobot_config.py): the LeRobot ``EnvConfig`` registered as type ``phantom_table``;
  ``make_phantom_vector_envs(cfg, n_envs, use_async_envs, suites)`` -> LIBERO-style {suite: {task_id: vec_env}}.

Gymnasium ids: ``lerobot_phantom/PhantomTable-v0`` (kwargs: suite, task_id, image_size, obs_type, render_mode,
episode_length, render_size) and one per suite, e.g. ``lerobot_phantom/PhantomTable-Goal-v0``. They are registered
without the order-enforcing wrapper so that ``task_description`` stays visible to lerobot-eval's ``add_envs_task``.
Action bounds, observation layout and grasping are documented in table_env.py.
"""

from __future__ import annotations

from typing import Any

from gymnasium.envs.registration import register, registry

from lerobot_phantom.envs.suites import SUITE_NAMES, SUITES

GYM_NAMESPACE = "lerobot_phantom"
GYM_ID = f"{GYM_NAMESPACE}/PhantomTable-v0"
ENTRY_POINT = "lerobot_phantom.envs.table_env:PhantomTableEnv"


def suite_gym_id(suite: str) -> str:
    return f"{GYM_NAMESPACE}/PhantomTable-{suite.capitalize()}-v0"


def register_gym_envs() -> None:
    """Register the gymnasium ids (idempotent)."""
    if GYM_ID not in registry:
        register(id=GYM_ID, entry_point=ENTRY_POINT, order_enforce=False, disable_env_checker=True)
    for suite in SUITE_NAMES:
        if suite_gym_id(suite) not in registry:
            register(
                id=suite_gym_id(suite),
                entry_point=ENTRY_POINT,
                kwargs={"suite": suite},
                order_enforce=False,
                disable_env_checker=True,
            )


register_gym_envs()

_LAZY = {
    "make_phantom_env": "lerobot_phantom.envs.table_env",
    "PhantomTableEnv": "lerobot_phantom.envs.table_env",
    "scripted_expert": "lerobot_phantom.envs.experts",
    "ScriptedExpert": "lerobot_phantom.envs.experts",
    "record_expert_episode": "lerobot_phantom.envs.experts",
    "collect": "lerobot_phantom.envs.collect",
    "CollectConfig": "lerobot_phantom.envs.collect",
    "PhantomTableEnvConfig": "lerobot_phantom.envs.lerobot_config",
    "make_phantom_vector_envs": "lerobot_phantom.envs.lerobot_config",
}

__all__ = ["GYM_ID", "SUITES", "SUITE_NAMES", "register_gym_envs", "suite_gym_id", *_LAZY]


def __getattr__(name: str) -> Any:
    # Building an env imports mujoco (and picks the GL backend); keep that off the package import path.
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
