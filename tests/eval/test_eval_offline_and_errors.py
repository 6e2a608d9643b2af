"""Offline mode (--dataset.*: action deviation on recorded frames) and clear errors on bad input."""

import sys

import eval_testkit as kit
import pytest
from lerobot.configs.default import DatasetConfig, EvalConfig

from lerobot_phantom.eval.config import EvalPhantomConfig, PhantomEvalConfig, check_policy_path
from lerobot_phantom.eval.eval import evaluate
from lerobot_phantom.eval.offline import frame_indices


@pytest.fixture(scope="module")
def dataset_root(tmp_path_factory):
    root = tmp_path_factory.mktemp("data") / "dot_reach"
    kit.write_toy_dataset(root)
    return root


def offline_cfg(root, out, **phantom):
    return PhantomEvalConfig(
        dataset=DatasetConfig(repo_id="local/dot_reach", root=str(root)),
        eval=EvalConfig(n_episodes=4, batch_size=4),
        output_dir=out,
        phantom=EvalPhantomConfig(**phantom),
    )


def test_offline_deviation_separates_image_and_state_policies(dataset_root, tmp_path):
    phantom = {
        "attacks": ["laser_blinding", "voice_dos"],
        "intensities": ["weak", "strong"],
        "offline_frames": 10,
    }
    colour = evaluate(
        offline_cfg(dataset_root, tmp_path / "c", **phantom), policy=kit.make_toy_policy("colour")
    )
    oracle = evaluate(
        offline_cfg(dataset_root, tmp_path / "o", **phantom), policy=kit.make_toy_policy("oracle")
    )
    assert colour["mode"] == "offline"
    assert colour["metadata"]["frame_indices"] == frame_indices(12, 10)
    by_key = {r["condition"]: r for r in colour["results"]}
    assert list(by_key) == ["laser_blinding@weak", "laser_blinding@strong", "voice_dos"]
    assert all(r["frames"] == 10 and len(r["per_frame_l2"]) == 10 for r in colour["results"])
    # Blinded, the colour policy no longer finds the target and stops: its action moves.
    assert by_key["laser_blinding@strong"]["mean_l2"] > 0.05
    assert by_key["laser_blinding@strong"]["mean_normalized"] > 0
    # Neither policy reads the instruction; the oracle reads no image: nothing moves.
    assert by_key["voice_dos"]["mean_l2"] == 0.0
    assert all(r["max_l2"] == 0.0 for r in oracle["results"])
    # The oracle reproduces the recorded (oracle) actions.
    assert oracle["metadata"]["clean_vs_recorded_l2"] < 1e-6
    assert (tmp_path / "c" / "eval.json").is_file()


def test_offline_refuses_temporal_options(dataset_root, tmp_path):
    cfg = offline_cfg(dataset_root, tmp_path, attacks=["laser_blinding"], intensities=["weak"], onset=3)
    with pytest.raises(ValueError, match=r"need rollouts"):
        evaluate(cfg, policy=kit.make_toy_policy("colour"))


def test_frame_indices_spread_evenly():
    assert frame_indices(10, 4) == [0, 3, 6, 9]
    assert frame_indices(3, 100) == [0, 1, 2]
    with pytest.raises(ValueError, match=r"no frames"):
        frame_indices(0, 4)


def test_unknown_attack_names_the_valid_ones():
    with pytest.raises(ValueError, match=r"unknown attack 'laser_beam'.*valid attacks: laser_blinding"):
        EvalPhantomConfig(attacks=["laser_beam"])


def test_bad_phantom_values_are_refused():
    with pytest.raises(ValueError, match=r"unknown intensity"):
        EvalPhantomConfig(intensities=["extreme"])
    with pytest.raises(ValueError, match=r"onset"):
        EvalPhantomConfig(onset=-1)
    with pytest.raises(ValueError, match=r"duration"):
        EvalPhantomConfig(duration=0)
    with pytest.raises(ValueError, match=r"instruction_mode"):
        EvalPhantomConfig(instruction_mode="loud")
    with pytest.raises(
        ValueError,
        match=r"--phantom\.intensity is a training option; in evaluation use --phantom\.intensities",
    ):
        EvalPhantomConfig(intensity="strong")
    with pytest.raises(ValueError, match=r"--phantom\.instruction_attacks is a training option"):
        EvalPhantomConfig(instruction_attacks=["voice_dos"])


def test_env_xor_dataset():
    with pytest.raises(ValueError, match=r"exactly one of --env\.type"):
        PhantomEvalConfig()
    with pytest.raises(ValueError, match=r"exactly one of --env\.type"):
        PhantomEvalConfig(env=kit.DotReachEnvConfig(), dataset=DatasetConfig(repo_id="local/x"))


def test_unknown_camera_lists_available(tmp_path):
    cfg = PhantomEvalConfig(
        env=kit.DotReachEnvConfig(),
        eval=EvalConfig(n_episodes=2, batch_size=2),
        output_dir=tmp_path,
        phantom=EvalPhantomConfig(attacks=["laser_blinding"], intensities=["weak"], cameras=["top"]),
    )
    with pytest.raises(
        ValueError, match=r"'top' is not a camera of this env; available: \['observation.images.front'"
    ):
        evaluate(cfg, policy=kit.make_toy_policy("colour"))


def test_missing_checkpoint_is_a_clear_error(tmp_path, monkeypatch):
    # The config reads --policy.path from the command line, as LeRobot's EvalPipelineConfig does.
    monkeypatch.setattr(
        sys, "argv", ["lerobot-phantom-eval", f"--policy.path={tmp_path / 'no_such_checkpoint'}"]
    )
    with pytest.raises(
        FileNotFoundError, match=r"does not exist locally and the Hugging Face hub is offline"
    ):
        PhantomEvalConfig(env=kit.DotReachEnvConfig())


def test_directory_without_config_is_not_a_checkpoint(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"is not a policy checkpoint: expected config\.json"):
        check_policy_path(str(tmp_path))
    (tmp_path / "config.json").write_text("{}")
    check_policy_path(str(tmp_path))


def test_no_policy_is_a_clear_error(tmp_path):
    cfg = PhantomEvalConfig(
        env=kit.DotReachEnvConfig(), eval=EvalConfig(n_episodes=2, batch_size=2), output_dir=tmp_path
    )
    with pytest.raises(ValueError, match=r"no policy to evaluate: pass --policy\.path"):
        evaluate(cfg)
