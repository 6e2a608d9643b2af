from dataclasses import dataclass

import draccus
import numpy as np
import pytest
from lerobot.envs.configs import EnvConfig
from lerobot.envs.factory import make_env
from lerobot.envs.utils import add_envs_task, env_to_policy_features, preprocess_observation
from lerobot.utils.constants import ACTION, OBS_STATE

from lerobot_phantom.envs import SUITES
from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig, make_phantom_vector_envs


@dataclass
class _CliWithEnv:
    env: EnvConfig


def test_registered_as_phantom_table_choice():
    assert EnvConfig.get_choice_class("phantom_table") is PhantomTableEnvConfig
    args = ["--env.type=phantom_table", "--env.task=long", "--env.task_id=2"]
    cfg = draccus.parse(_CliWithEnv, args=args).env
    assert isinstance(cfg, PhantomTableEnvConfig) and cfg.type == "phantom_table"
    assert cfg.gym_kwargs["suite"] == "long" and cfg.gym_kwargs["task_id"] == 2


def test_policy_features_follow_lerobot_naming():
    features = env_to_policy_features(PhantomTableEnvConfig(task="goal", observation_height=64))
    assert features["observation.images.front"].shape == (3, 64, 96)
    assert features["observation.images.wrist"].shape == (3, 64, 96)
    assert features[OBS_STATE].shape == (4,)
    assert features[ACTION].shape == (4,)


def test_invalid_config_values_name_valid_ones():
    with pytest.raises(ValueError, match="valid: spatial, object, goal, long"):
        PhantomTableEnvConfig(task="libero_10")
    with pytest.raises(ValueError, match=r"valid 0\.\.3"):
        PhantomTableEnvConfig(task="spatial", task_id=4)
    with pytest.raises(ValueError, match="obs_type"):
        PhantomTableEnvConfig(obs_type="state")
    with pytest.raises(ValueError, match="empty instructions"):
        PhantomTableEnvConfig(disable_env_checker=False)


def test_stock_make_env_passes_the_instruction_as_task():
    envs = make_env(PhantomTableEnvConfig(task="object", task_id=1), n_envs=2)
    vec = envs["phantom_table"][0]
    try:
        obs, _ = vec.reset(seed=[0, 1])
        batch = add_envs_task(vec, preprocess_observation(obs))
        assert batch["task"] == [SUITES["object"][1]["language"]] * 2
        assert batch["observation.images.front"].shape == (2, 3, 96, 96)
        assert batch[OBS_STATE].shape == (2, 4)
        assert vec.call("_max_episode_steps") == (80, 80)
        _, _, _, _, info = vec.step(np.zeros((2, 4), dtype=np.float32))
        assert "is_success" in info
    finally:
        vec.close()


def test_nested_vector_envs_per_suite_and_task():
    envs = make_phantom_vector_envs(PhantomTableEnvConfig(), n_envs=1, suites="spatial,long")
    try:
        assert {suite: sorted(tasks) for suite, tasks in envs.items()} == {
            "spatial": [0, 1, 2, 3],
            "long": [0, 1, 2, 3],
        }
        vec = envs["long"][3]
        vec.reset(seed=[0])
        assert vec.call("task_description") == (SUITES["long"][3]["language"],)
    finally:
        for tasks in envs.values():
            for vec in tasks.values():
                vec.close()
    with pytest.raises(ValueError, match="'all'"):
        make_phantom_vector_envs(PhantomTableEnvConfig(), suites="kitchen")


@pytest.mark.timeout(120)
def test_async_vector_env_works_after_the_parent_rendered():
    """LeRobot's use_async_envs forks; forked children must still render once the parent holds a GL context."""
    import gymnasium as gym

    from lerobot_phantom.envs import GYM_ID, make_phantom_env

    parent = make_phantom_env("goal", seed=0)
    vec = gym.vector.AsyncVectorEnv(
        [lambda: gym.make(GYM_ID, suite="long", task_id=1) for _ in range(2)],
        autoreset_mode=gym.vector.AutoresetMode.SAME_STEP,
    )
    try:
        obs, _ = vec.reset(seed=[0, 1])
        assert obs["pixels"]["front"].shape == (2, 96, 96, 3)
        assert obs["pixels"]["front"][0].std() > 0
        assert not np.array_equal(obs["pixels"]["front"][0], obs["pixels"]["front"][1])
    finally:
        vec.close()
        parent.close()
