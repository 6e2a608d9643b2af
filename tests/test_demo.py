"""The README's main job (``lerobot-phantom-demo``) must keep working on a fresh machine: these tests run it."""

import json
from pathlib import Path

import pytest

from lerobot_phantom.demo import DemoConfig, demo, recipe_policy_flags

CPU_RECIPE = Path(__file__).resolve().parents[1] / "configs" / "smolvla_goal_cpu.json"


def test_gallery_only_writes_the_gallery_and_refuses_to_overwrite(tmp_path):
    out = tmp_path / "demo"
    outputs = demo(DemoConfig(out=str(out), gallery_only=True))
    assert outputs["gallery"].stat().st_size > 10_000
    assert "$ lerobot-phantom-viz" in outputs["log"].read_text()
    with pytest.raises(FileExistsError, match="--overwrite"):
        demo(DemoConfig(out=str(out), gallery_only=True))
    assert outputs["gallery"].exists()  # the refused run lost nothing


def test_unknown_suite_is_refused_naming_the_valid_ones(tmp_path):
    with pytest.raises(ValueError, match="spatial, object, goal, long"):
        demo(DemoConfig(out=str(tmp_path / "demo"), suite="kitchen"))


def test_clean_policy_without_a_checkpoint_is_refused(tmp_path):
    with pytest.raises(FileNotFoundError, match="pretrained_model"):
        demo(DemoConfig(out=str(tmp_path / "demo"), clean_policy=str(tmp_path / "nothing")))
    assert not (tmp_path / "demo").exists()


def test_a_study_policy_in_the_working_directory_is_used_the_selected_checkpoint_first(tmp_path, monkeypatch):
    from lerobot_phantom.demo import _trained_policy

    monkeypatch.chdir(tmp_path)
    cfg = DemoConfig(out="demo")
    assert _trained_policy(cfg) is None  # no study here: the demo trains its own
    study = Path("outputs/study/train")
    for run in ("clean", "selected"):
        (study / run / "checkpoints/last/pretrained_model").mkdir(parents=True)
    (study / "clean/checkpoints/last/pretrained_model/config.json").write_text("{}")
    assert _trained_policy(cfg) == study / "clean/checkpoints/last/pretrained_model"
    (study / "selected/checkpoints/last/pretrained_model/config.json").write_text("{}")
    assert _trained_policy(cfg) == study / "selected/checkpoints/last/pretrained_model"
    assert _trained_policy(DemoConfig(out="demo", use_study_policy=False)) is None
    assert _trained_policy(DemoConfig(out="demo", clean_policy="mine")) == Path("mine")


def test_demo_trains_with_the_shipped_cpu_recipe(tmp_path):
    """The demo's clean training is configs/smolvla_goal_cpu.json at a smaller scale, never LeRobot's frozen-VLM
    defaults (which keep the weight-free VLM at its random initialisation). The learning rate is the one scale
    setting that differs: constant as in the recipe, but 3e-4, which learns faster in a 500-step run."""
    flags = dict(
        flag.removeprefix("--").split("=", 1) for flag in recipe_policy_flags(DemoConfig(), tmp_path)
    )
    recipe = json.loads(CPU_RECIPE.read_text())["policy"]
    compared = (
        "load_vlm_weights",
        "freeze_vision_encoder",
        "train_expert_only",
        "resize_imgs_with_padding",
        "chunk_size",
        "n_action_steps",
    )
    for key in compared:
        assert json.loads(flags[f"policy.{key}"]) == recipe[key], key
    assert recipe["optimizer_lr"] == recipe["scheduler_decay_lr"]
    assert (
        flags["policy.optimizer_lr"] == flags["policy.scheduler_decay_lr"] == str(DemoConfig().learning_rate)
    )
    assert flags["policy.freeze_vision_encoder"] == flags["policy.train_expert_only"] == "false"


@pytest.mark.slow
def test_the_whole_loop_runs_at_microscopic_scale(tmp_path):
    outputs = demo(
        DemoConfig(
            out=str(tmp_path / "demo"),
            episodes=2,
            vlm_size="tiny",
            use_study_policy=False,
            chunk_size=4,
            n_action_steps=4,
            clean_steps=2,
            phantom_steps=2,
            batch_size=2,
            eval_episodes=1,
            servo_episodes=2,
            attacks="[laser_blinding,voice_dos]",
            intensities="[strong]",
        )
    )
    servo = json.loads(outputs["eval_servo"].read_text())
    conditions = {r["condition"] for r in servo["results"]}
    assert conditions == {"clean", "laser_blinding@strong", "voice_dos"}
    # the reference policy obeys an empty instruction by not moving: voice DoS can never succeed
    assert all(r["successes"] == 0 for r in servo["results"] if r["condition"] == "voice_dos")
    before = json.loads(outputs["eval_before"].read_text())
    after = json.loads(outputs["eval_after"].read_text())
    assert before["metadata"]["episode_seeds"] == after["metadata"]["episode_seeds"]
    assert (outputs["report_servo"] / "robustness.md").exists()
    assert (outputs["report"] / "before_after.md").exists()
    assert (outputs["phantom_policy"] / "adapter_config.json").exists()  # stage 2 saved a LoRA adapter
