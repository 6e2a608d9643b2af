"""The two CLIs end to end: a real LeRobot policy checkpoint (ACT, random weights) loaded from --policy.path,
evaluated on phantom_table under attack, then reported."""

import json
import sys

import pytest
from lerobot.configs.default import DatasetConfig, EvalConfig
from lerobot.configs.policies import PreTrainedConfig
from lerobot.policies.act.configuration_act import ACTConfig
from lerobot.policies.factory import make_policy, make_pre_post_processors

from lerobot_phantom.envs.collect import CollectConfig, collect
from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig
from lerobot_phantom.eval import eval as eval_module
from lerobot_phantom.eval import report as report_module
from lerobot_phantom.eval.config import EvalPhantomConfig, PhantomEvalConfig
from lerobot_phantom.eval.eval import evaluate


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory):
    """A real LeRobot checkpoint (config, weights, processors) of a small ACT for phantom_table's features."""
    checkpoint = tmp_path_factory.mktemp("act") / "checkpoint"
    act = ACTConfig(
        pretrained_backbone_weights=None,
        dim_model=32,
        dim_feedforward=64,
        n_heads=2,
        n_encoder_layers=1,
        n_decoder_layers=1,
        chunk_size=5,
        n_action_steps=5,
        use_vae=False,
        device="cpu",
    )
    policy = make_policy(act, env_cfg=PhantomTableEnvConfig(task="goal"))
    preprocessor, postprocessor = make_pre_post_processors(act, dataset_stats=None)
    for part in (policy, preprocessor, postprocessor):
        part.save_pretrained(checkpoint)
    return checkpoint


@pytest.mark.slow  # draccus builds every LeRobot choice's help (~10 s) and ACT runs on MuJoCo frames
def test_eval_cli_with_checkpoint_then_report(checkpoint, tmp_path, monkeypatch):

    out = tmp_path / "eval"
    monkeypatch.setattr(
        sys,
        "argv",
        [
            "lerobot-phantom-eval",
            f"--policy.path={checkpoint}",
            "--env.type=phantom_table",
            "--env.task=goal",
            "--env.episode_length=6",
            "--eval.n_episodes=2",
            "--eval.batch_size=2",
            "--seed=11",
            "--phantom.attacks=[laser_blinding,voice_dos]",
            "--phantom.intensities=[strong]",
            "--phantom.videos=1",
            f"--output_dir={out}",
        ],
    )
    eval_module.main()
    data = json.loads((out / "eval.json").read_text())
    assert data["metadata"]["policy"] == {"path": str(checkpoint), "type": "act"}
    assert data["metadata"]["env"] == {"type": "phantom_table", "task": "goal"}
    assert data["metadata"]["episode_seeds"] == [11, 12]
    assert [r["condition"] for r in data["summary"]] == ["clean", "laser_blinding@strong", "voice_dos"]
    assert all(r["episodes"] == 2 and r["suite"] == "goal" for r in data["results"])
    assert all(e["steps"] <= 6 for r in data["results"] for e in r["per_episode"])
    assert len(list((out / "videos").rglob("*.mp4"))) == 3

    monkeypatch.setattr(
        sys, "argv", ["lerobot-phantom-report", f"--inputs=[{out}]", f"--output_dir={tmp_path / 'report'}"]
    )
    report_module.main()
    table = (tmp_path / "report" / "robustness.md").read_text().splitlines()
    assert table[0] == "| Attack | goal |"
    assert [line.split(" | ")[0] for line in table[2:5]] == [
        "| Clean",
        "| Laser blinding (LB), strong",
        "| Voice DoS (VD)",
    ]


@pytest.mark.slow  # collects an expert episode in MuJoCo, then runs ACT on its frames
def test_offline_mode_loads_the_checkpoint_for_a_recorded_dataset(checkpoint, tmp_path):
    root = tmp_path / "recorded"
    collect(CollectConfig(suite="goal", episodes=1, root=str(root), repo_id="local/recorded", progress=False))
    policy_cfg = PreTrainedConfig.from_pretrained(checkpoint)
    policy_cfg.pretrained_path = checkpoint
    cfg = PhantomEvalConfig(
        dataset=DatasetConfig(repo_id="local/recorded", root=str(root)),
        policy=policy_cfg,
        eval=EvalConfig(n_episodes=8, batch_size=8),
        output_dir=tmp_path / "offline",
        phantom=EvalPhantomConfig(
            attacks=["laser_blinding", "voice_dos"], intensities=["strong"], offline_frames=8
        ),
    )
    data = evaluate(cfg)
    assert data["metadata"]["policy"]["type"] == "act"
    by_key = {r["condition"]: r for r in data["results"]}
    assert set(by_key) == {"laser_blinding@strong", "voice_dos"}
    assert all(r["frames"] == 8 for r in data["results"])
    # ACT reads the cameras, not the instruction.
    assert by_key["laser_blinding@strong"]["mean_l2"] > 0
    assert by_key["voice_dos"]["max_l2"] == 0.0
