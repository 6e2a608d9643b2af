"""Rollouts under attack on a tiny LeRobot env (tests/eval/eval_testkit.py) with real LeRobot test policies."""

import json
import random

import eval_testkit as kit
import pytest
from lerobot.configs.default import EvalConfig

from lerobot_phantom.eval.config import EvalPhantomConfig, PhantomEvalConfig
from lerobot_phantom.eval.eval import EVAL_FILENAME, evaluate
from lerobot_phantom.eval.rollout import Condition, build_conditions

CAMERA_STRONG = ["laser_blinding", "em_truncation", "laser_color_strip"]


def make_cfg(tmp_path, n_episodes=8, batch_size=4, **phantom):
    return PhantomEvalConfig(
        env=kit.DotReachEnvConfig(),
        eval=EvalConfig(n_episodes=n_episodes, batch_size=batch_size),
        output_dir=tmp_path / "out",
        seed=7,
        phantom=EvalPhantomConfig(**phantom),
    )


def tsr(report, condition):
    (row,) = [r for r in report["summary"] if r["condition"] == condition]
    return row["tsr"]


@pytest.fixture(scope="module")
def colour_report(tmp_path_factory):
    cfg = make_cfg(
        tmp_path_factory.mktemp("colour"),
        attacks=[*CAMERA_STRONG, "voice_dos"],
        intensities=["strong"],
        videos=1,
    )
    return evaluate(cfg, policy=kit.make_toy_policy("colour")), cfg


def test_oracle_policy_is_unhurt_by_camera_attacks(tmp_path):
    cfg = make_cfg(tmp_path, attacks=CAMERA_STRONG, intensities=["weak", "strong"])
    report = evaluate(cfg, policy=kit.make_toy_policy("oracle"))
    assert [r["condition"] for r in report["summary"]] == [c.key for c in build_conditions(cfg.phantom)]
    for row in report["summary"]:
        assert row["episodes"] == 8
        assert row["tsr"] == 1.0, row


def test_image_policy_loses_success_under_strong_camera_attacks(colour_report):
    report, _ = colour_report
    assert tsr(report, "clean") == 1.0
    assert tsr(report, "laser_blinding@strong") < 0.5
    strong = [tsr(report, f"{a}@strong") for a in CAMERA_STRONG]
    assert sum(strong) / len(strong) < 0.75
    # The colour policy ignores the instruction, so removing it changes nothing.
    assert tsr(report, "voice_dos") == 1.0


def test_paired_seeds_identical_across_conditions_and_recorded(colour_report):
    report, cfg = colour_report
    on_disk = json.loads((cfg.output_dir / EVAL_FILENAME).read_text())
    assert on_disk == json.loads(json.dumps(report))
    expected = list(range(7, 7 + 8))
    assert on_disk["metadata"]["episode_seeds"] == expected
    for row in on_disk["results"]:
        assert [e["seed"] for e in row["per_episode"]] == expected
        assert row["successes"] == sum(e["success"] for e in row["per_episode"])
        low, high = row["ci95"]
        assert low <= row["tsr"] <= high
    meta = on_disk["metadata"]
    assert meta["env"]["type"] == "phantom_test_dot"
    assert set(meta["versions"]) >= {"lerobot", "lerobot_phantom", "torch"}
    assert meta["phantom"]["intensities"] == ["strong"]


def test_attack_parameters_fixed_per_episode_and_reproducible(colour_report, tmp_path):
    report, _ = colour_report
    first = {r["condition"]: [e["attack_params"] for e in r["per_episode"]] for r in report["results"]}
    assert first["clean"][0] == {}
    assert set(first["laser_blinding@strong"][0]) == {"front"}  # the front camera only, as in the paper
    again = evaluate(
        make_cfg(tmp_path, n_episodes=8, batch_size=8, attacks=["laser_blinding"], intensities=["strong"]),
        policy=kit.make_toy_policy("colour"),
    )
    # Same seeds, another batch size: the same per-episode attack and the same outcomes.
    rerun = {r["condition"]: r for r in again["results"]}["laser_blinding@strong"]
    original = {r["condition"]: r for r in report["results"]}["laser_blinding@strong"]
    assert [e["attack_params"] for e in rerun["per_episode"]] == [
        e["attack_params"] for e in original["per_episode"]
    ]
    assert [e["success"] for e in rerun["per_episode"]] == [e["success"] for e in original["per_episode"]]


def test_videos_written_for_first_episodes_of_each_condition(colour_report):
    _, cfg = colour_report
    videos = sorted(
        p.relative_to(cfg.output_dir / "videos").as_posix()
        for p in (cfg.output_dir / "videos").rglob("*.mp4")
    )
    assert len(videos) == len(build_conditions(cfg.phantom))
    assert "clean/DotReach-v0_0/episode_seed7.mp4" in videos
    assert all(p.endswith("episode_seed7.mp4") for p in videos)


def test_instruction_attacks_reach_the_task_text(tmp_path):
    cfg = make_cfg(
        tmp_path,
        n_episodes=4,
        attacks=["voice_dos", "voice_spoofing", "laser_blinding"],
        intensities=["strong"],
    )
    report = evaluate(cfg, policy=kit.make_toy_policy("instructed"))
    assert tsr(report, "clean") == 1.0
    assert tsr(report, "voice_dos") == 0.0  # the instruction is gone: the policy does not move
    assert tsr(report, "voice_spoofing") == 1.0  # the original text is kept in the paper's mode
    assert tsr(report, "laser_blinding@strong") == 1.0  # reads true state, not the image


def test_onset_after_the_episode_leaves_it_clean_and_short_duration_is_partial(tmp_path):
    late = evaluate(
        make_cfg(tmp_path / "late", attacks=["laser_blinding"], intensities=["strong"], onset=kit.MAX_STEPS),
        policy=kit.make_toy_policy("colour"),
    )
    assert tsr(late, "laser_blinding@strong") == 1.0
    # Blinded for the first 2 steps only: the policy waits, then still has time to reach the target.
    brief = evaluate(
        make_cfg(tmp_path / "brief", attacks=["laser_blinding"], intensities=["strong"], onset=0, duration=2),
        policy=kit.make_toy_policy("colour"),
    )
    assert tsr(brief, "laser_blinding@strong") == 1.0
    steps_clean = [e["steps"] for e in brief["results"][0]["per_episode"]]
    steps_brief = [e["steps"] for e in brief["results"][1]["per_episode"]]
    assert all(b == c + 2 for b, c in zip(steps_brief, steps_clean, strict=True))


def test_condition_keys():
    assert Condition("clean").key == "clean"
    assert Condition("laser_blinding", "weak").key == "laser_blinding@weak"
    assert Condition("voice_dos").key == "voice_dos"
    assert Condition("laser_blinding", "0.5").intensity_value == 0.5


def attacked_cameras(report, condition):
    (row,) = [r for r in report["results"] if r["condition"] == condition]
    return [sorted(e["attack_params"]) for e in row["per_episode"]]


def test_camera_selection(tmp_path):
    def run(cameras, name):
        cfg = make_cfg(tmp_path / name, attacks=["laser_blinding"], intensities=["strong"], cameras=cameras)
        return evaluate(cfg, policy=kit.make_toy_policy("colour"))

    wrist = run(["wrist"], "wrist")
    assert attacked_cameras(wrist, "laser_blinding@strong") == [["wrist"]] * 8
    assert tsr(wrist, "laser_blinding@strong") == 1.0  # the colour policy only looks at the front camera
    every = run(["all"], "all")
    assert attacked_cameras(every, "laser_blinding@strong") == [["front", "wrist"]] * 8
    assert tsr(every, "laser_blinding@strong") == 0.0
    one = run(["random"], "random")
    picks = attacked_cameras(one, "laser_blinding@strong")
    assert all(len(p) == 1 for p in picks) and {p[0] for p in picks} == {"front", "wrist"}
    # Exactly the episodes whose front camera was picked are lost.
    (row,) = [r for r in one["results"] if r["condition"] == "laser_blinding@strong"]
    assert [not e["success"] for e in row["per_episode"]] == [p == ["front"] for p in picks]


def test_each_episode_records_its_task_before_any_instruction_attack(tmp_path):
    cfg = make_cfg(tmp_path, n_episodes=8, attacks=["voice_dos"], intensities=["strong"])
    report = evaluate(cfg, policy=kit.make_toy_policy("instructed"))
    clean, muted = report["results"]
    tasks = [(e["task_index"], e["task"], e["instruction"]) for e in clean["per_episode"]]
    # The same seeds draw the same tasks in every condition, and the recorded instruction is the env's, not the
    # attacked (emptied) one the policy saw.
    assert tasks == [(e["task_index"], e["task"], e["instruction"]) for e in muted["per_episode"]]
    assert {t for t in tasks} <= {(i, kit.TASK_NAMES[i], kit.INSTRUCTIONS[i]) for i in range(2)}
    assert len({t[0] for t in tasks}) == 2, "8 seeds should draw both tasks"
    per_task = report["summary_per_task"]
    assert {(r["condition"], r["task"]) for r in per_task} == {
        (c, name) for c in ("clean", "voice_dos") for name in {t[1] for t in tasks}
    }
    for row in per_task:
        expected = [
            e for r in report["results"] if r["condition"] == row["condition"] for e in r["per_episode"]
        ]
        expected = [e for e in expected if e["task"] == row["task"]]
        assert row["episodes"] == len(expected)
        assert row["successes"] == sum(e["success"] for e in expected)
        assert row["instruction"] == kit.INSTRUCTIONS[row["task_index"]]
    # Per task, the pooled counts add up.
    for summary in report["summary"]:
        rows = [r for r in per_task if r["condition"] == summary["condition"]]
        assert sum(r["episodes"] for r in rows) == summary["episodes"]
        assert sum(r["successes"] for r in rows) == summary["successes"]


def test_format_summary_has_a_column_per_task(tmp_path):
    from lerobot_phantom.eval.eval import format_summary

    report = evaluate(make_cfg(tmp_path, n_episodes=8, attacks=[]), policy=kit.make_toy_policy("oracle"))
    text = format_summary(report)
    assert "95% Wilson CI" in text
    legend = {line.strip() for line in text.splitlines() if line.strip().startswith(("T0:", "T1:"))}
    assert {entry.split(" / ")[1] for entry in legend} == set(kit.TASK_NAMES)
    (clean_line,) = [line for line in text.splitlines()[-1:] if line.startswith("clean")]
    assert clean_line.split()[1:] == ["100.0", "100.0"]  # the oracle solves both tasks


def test_resume_keeps_finished_conditions_and_runs_the_rest(tmp_path):
    full = evaluate(
        make_cfg(tmp_path / "full", attacks=["laser_blinding", "em_truncation"], intensities=["strong"]),
        policy=kit.make_toy_policy("colour"),
    )
    # An interrupted run: only the clean control and the first attack were written.
    cfg = make_cfg(tmp_path / "resumed", attacks=["laser_blinding", "em_truncation"], intensities=["strong"])
    partial = json.loads(json.dumps(full))
    partial["results"] = partial["results"][:2]
    partial["metadata"]["complete"] = False
    marker = random.Random(0).random()
    partial["results"][1]["marker"] = marker  # a kept row is copied, not recomputed
    cfg.output_dir.mkdir(parents=True)
    (cfg.output_dir / EVAL_FILENAME).write_text(json.dumps(partial))
    cfg.resume = True
    resumed = evaluate(cfg, policy=kit.make_toy_policy("colour"))
    assert resumed["metadata"]["complete"] is True
    assert resumed["results"][1]["marker"] == marker
    assert [r["condition"] for r in resumed["results"]] == [r["condition"] for r in full["results"]]
    assert resumed["results"][2]["per_episode"] == full["results"][2]["per_episode"]
    # Other settings: refused, naming what differs.
    other = make_cfg(tmp_path / "resumed", n_episodes=4, attacks=["laser_blinding"], intensities=["strong"])
    other.resume = True
    with pytest.raises(ValueError, match="n_episodes"):
        evaluate(other, policy=kit.make_toy_policy("colour"))


def test_a_calibration_set_gives_its_physics_to_the_attacks_it_calibrates(tmp_path):
    # The study's calibrated-physics sweeps pass one set for all attacks (DIR/<attack>/calibrated.json).
    folder = tmp_path / "calibration" / "laser_blinding"
    folder.mkdir(parents=True)
    kwargs = {"model": "physical", "gain": 1.5, "auto_exposure": 2.0}
    payload = {"format": 1, "attack": "laser_blinding", "kwargs": kwargs}
    (folder / "calibrated.json").write_text(json.dumps(payload))
    cfg = make_cfg(
        tmp_path,
        n_episodes=2,
        batch_size=2,
        attacks=["laser_blinding", "em_truncation"],
        intensities=["strong"],
        calibration=str(folder.parent),
    )
    evaluate(cfg, policy=kit.make_toy_policy("oracle"))
    meta = json.loads((cfg.output_dir / EVAL_FILENAME).read_text())["metadata"]
    assert meta["calibrated_attacks"] == ["laser_blinding"]
    assert "physical" in meta["attacks"]["laser_blinding@strong"]
    with pytest.raises(ValueError, match=r"calibrates \['laser_blinding'\], not 'em_truncation'"):
        evaluate(
            make_cfg(tmp_path / "b", attacks=["em_truncation"], calibration=str(folder.parent)),
            policy=kit.make_toy_policy("oracle"),
        )
