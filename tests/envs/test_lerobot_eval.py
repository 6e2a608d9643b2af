"""Stock ``lerobot-eval`` (LeRobot 0.4.4) on ``--env.type=phantom_table`` with a tiny offline ACT checkpoint."""

import json
import sys

import pytest
from lerobot.configs.types import FeatureType
from lerobot.envs.utils import env_to_policy_features
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.policies.act.modeling_act import ACTPolicy
from lerobot.policies.factory import make_pre_post_processors

from lerobot_phantom.envs import SUITES
from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig


def save_tiny_act_checkpoint(path, env_cfg):
    """A randomly initialised, very small ACT (no pretrained backbone, nothing from the hub) + its processors."""
    features = env_to_policy_features(env_cfg)
    cfg = ACTConfig(
        input_features={k: v for k, v in features.items() if v.type is not FeatureType.ACTION},
        output_features={k: v for k, v in features.items() if v.type is FeatureType.ACTION},
        pretrained_backbone_weights=None,
        chunk_size=4,
        n_action_steps=4,
        dim_model=16,
        n_heads=2,
        dim_feedforward=32,
        n_encoder_layers=1,
        n_decoder_layers=1,
        use_vae=False,
        device="cpu",
        push_to_hub=False,
    )
    policy = ACTPolicy(cfg)
    preprocessor, postprocessor = make_pre_post_processors(cfg, dataset_stats=None)
    for artefact in (policy, preprocessor, postprocessor):
        artefact.save_pretrained(path)


@pytest.mark.slow
def test_stock_lerobot_eval_runs_one_episode_and_the_policy_gets_the_instruction(tmp_path, monkeypatch):
    from lerobot.scripts.lerobot_eval import eval_main

    checkpoint = tmp_path / "ckpt"
    save_tiny_act_checkpoint(checkpoint, PhantomTableEnvConfig(task="goal"))
    seen_tasks = []
    original_select_action = ACTPolicy.select_action

    def spying_select_action(self, batch, *args, **kwargs):
        seen_tasks.append(batch.get("task"))
        return original_select_action(self, batch, *args, **kwargs)

    monkeypatch.setattr(ACTPolicy, "select_action", spying_select_action)
    out = tmp_path / "eval"
    argv = [
        "lerobot-eval",
        f"--policy.path={checkpoint}",
        "--policy.device=cpu",
        "--env.type=phantom_table",
        "--env.task=goal",
        "--env.task_id=2",
        "--env.episode_length=3",
        "--eval.n_episodes=1",
        "--eval.batch_size=1",
        f"--output_dir={out}",
        "--seed=0",
    ]
    monkeypatch.setattr(sys, "argv", argv)
    eval_main()

    info = json.loads((out / "eval_info.json").read_text())
    assert info["overall"]["n_episodes"] == 1
    assert set(info["per_group"]) == {"phantom_table"}
    assert len(seen_tasks) == 3
    assert all(task == [SUITES["goal"][2]["language"]] for task in seen_tasks)
