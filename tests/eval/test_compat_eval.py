"""The LeRobot seams lerobot_phantom.eval leans on (evaluation section of _lerobot_compat): fail loudly if they move."""

import inspect

import eval_testkit as kit
import numpy as np
from lerobot.envs.utils import preprocess_observation
from lerobot.processor import DataProcessorPipeline

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.eval.rollout import image_keys


def test_rollout_signature():
    parameters = list(inspect.signature(compat.eval_rollout()).parameters)
    assert parameters == list(compat.EVAL_ROLLOUT_PARAMETERS)


def test_env_processors_are_pipelines_with_steps():
    pre, post = compat.eval_env_processors(kit.DotReachEnvConfig(), kit.ToyPolicyConfig())
    assert isinstance(pre, DataProcessorPipeline) and isinstance(post, DataProcessorPipeline)
    assert list(pre.steps) == [] and list(post.steps) == []


def test_observation_keys_the_attack_step_expects():
    env = kit.DotReachEnv()
    obs, _ = env.reset(seed=0)
    batch = {
        k: (np.stack([v]) if not isinstance(v, dict) else {c: np.stack([i]) for c, i in v.items()})
        for k, v in obs.items()
    }
    observation = preprocess_observation(batch)
    assert image_keys(observation) == ["observation.images.front", "observation.images.wrist"]
    assert observation["observation.images.front"].dtype.is_floating_point


def test_video_writer_and_seeding(tmp_path):
    frames = np.zeros((3, 16, 16, 3), np.uint8)
    compat.eval_write_video(tmp_path / "v.mp4", frames, 10)
    assert (tmp_path / "v.mp4").stat().st_size > 0
    import torch

    compat.eval_seed_everything(5)
    a = torch.rand(2)
    compat.eval_seed_everything(5)
    assert torch.equal(a, torch.rand(2))
