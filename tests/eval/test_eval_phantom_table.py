"""lerobot-phantom-eval on the built-in phantom_table benchmark, built by LeRobot's own make_env."""

import eval_testkit as kit
import pytest
import torch
from lerobot.configs.default import EvalConfig
from lerobot.envs.factory import make_env

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig
from lerobot_phantom.envs.suites import get_task
from lerobot_phantom.eval.config import EvalPhantomConfig, PhantomEvalConfig
from lerobot_phantom.eval.eval import evaluate

pytestmark = pytest.mark.slow  # MuJoCo rollouts: ~10-20 s on 2 shared cores


def test_scripted_expert_is_perfect_and_untouched_by_camera_attacks(tmp_path):
    env_cfg = PhantomTableEnvConfig(task="goal")
    envs = make_env(env_cfg, n_envs=2)
    try:
        policy = kit.PhantomTableExpertPolicy(kit.ToyPolicyConfig()).bind(envs["phantom_table"][0])
        cfg = PhantomEvalConfig(
            env=env_cfg,
            eval=EvalConfig(n_episodes=2, batch_size=2),
            output_dir=tmp_path,
            seed=3,
            phantom=EvalPhantomConfig(attacks=["laser_blinding", "voice_dos"], intensities=["strong"]),
        )
        report = evaluate(cfg, policy=policy, envs=envs)
    finally:
        compat.eval_close_envs(envs)
    assert report["metadata"]["suites"] == ["goal"]
    assert [r["condition"] for r in report["summary"]] == ["clean", "laser_blinding@strong", "voice_dos"]
    assert all(r["tsr"] == 1.0 for r in report["summary"])
    # Same seeds -> same initial states -> the state-reading expert takes the same number of steps everywhere.
    steps = {r["condition"]: [e["steps"] for e in r["per_episode"]] for r in report["results"]}
    assert steps["laser_blinding@strong"] == steps["clean"] == steps["voice_dos"]
    clean, blinded, muted = policy.first_images
    # The attack reached the front camera the policy sees, and only the front camera.
    assert (blinded["front"] - clean["front"]).abs().mean() > 0.1
    assert torch.equal(blinded["wrist"], clean["wrist"])
    assert torch.equal(muted["front"], clean["front"])
    # Each episode names the goal the env drew for it (suite task index, name and instruction), whatever the attack.
    for row in report["results"]:
        for episode in row["per_episode"]:
            task = get_task("goal", episode["task_index"])
            assert (episode["task"], episode["instruction"]) == (task["name"], task["language"])
        assert [e["task_index"] for e in row["per_episode"]] == [
            e["task_index"] for e in report["results"][0]["per_episode"]
        ]
    assert {r["task"] for r in report["summary_per_task"]} == {
        e["task"] for e in report["results"][0]["per_episode"]
    }
