"""The study's stage logic: the plan, fingerprints, skip/resume/run decisions, the config's checks."""

import dataclasses
import json
import shutil

import pytest
from study_testkit import micro_config

from lerobot_phantom.study.config import (
    BeyondSettings,
    LoRASettings,
    SelectSettings,
    StudyConfig,
    SweepSettings,
)
from lerobot_phantom.study.stages import (
    PRETRAINED,
    RESUME,
    RUN,
    SKIP,
    Stage,
    decide,
    fingerprints,
    plan,
)
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS

PAPER_LOOP = [
    "collect",
    "vlm",
    "train_clean",
    "sweep_validation_000001",  # the micro run saves a checkpoint at steps 1 and 2
    "sweep_validation_000002",
    "select_clean",
    "sweep_before",
    "train_at",
    "train_control",
    "sweep_after",
    "sweep_control",
    "report",
]


def by_name(stages):
    return {s.name: s for s in stages}


def flag(stage: Stage, name: str) -> str:
    (value,) = [a.split("=", 1)[1] for a in stage.args if a.startswith(f"--{name}=")]
    return value


def test_paper_loop_in_dependency_order(micro):
    stages = plan(micro)
    assert [s.name for s in stages] == PAPER_LOOP
    seen = set()
    for stage in stages:
        assert set(stage.depends) <= seen, stage.name
        seen.add(stage.name)
    s = by_name(stages)
    assert s["train_at"].depends == ("select_clean",) == s["train_control"].depends
    assert s["sweep_before"].depends == ("select_clean",)
    assert s["select_clean"].depends == ("sweep_validation_000001", "sweep_validation_000002")
    assert s["sweep_after"].depends == ("train_at",)
    assert {x.role for x in stages if x.kind == "sweep"} == {None, "before", "after", "control"}


def test_without_selection_everything_starts_from_the_last_clean_checkpoint(micro):
    cfg = dataclasses.replace(micro, select=dataclasses.replace(micro.select, enabled=False))
    s = by_name(plan(cfg))
    assert list(s) == [n for n in PAPER_LOOP if not n.startswith(("sweep_validation", "select"))]
    assert flag(s["sweep_before"], "policy.path") == f"train/clean/{PRETRAINED}"
    assert flag(s["train_at"], "policy.path") == f"train/clean/{PRETRAINED}"
    assert s["train_at"].depends == ("train_clean",)


def test_selection_evaluates_every_saved_checkpoint_clean_on_validation_seeds(tmp_path):
    # 5 steps saved every 2: LeRobot writes checkpoints 2, 4 and the last step 5.
    cfg = micro_config(
        tmp_path, train=dataclasses.replace(micro_config(tmp_path).train, steps=5, save_freq=2)
    )
    s = by_name(plan(cfg))
    validations = [x for x in s.values() if x.name.startswith("sweep_validation_")]
    assert [x.name for x in validations] == [f"sweep_validation_00000{i}" for i in (2, 4, 5)]
    checkpoints = [flag(x, "policy.path") for x in validations]
    assert checkpoints == [f"train/clean/checkpoints/00000{i}/pretrained_model" for i in (2, 4, 5)]
    for x in validations:
        assert x.role is None and x.depends == ("train_clean",)
        assert json.loads(flag(x, "phantom.attacks")) == []
        assert flag(x, "seed") == str(cfg.select.seed) != flag(s["sweep_before"], "seed")
        assert flag(x, "eval.n_episodes") == str(cfg.select.n_episodes)
    select = s["select_clean"]
    assert json.loads(flag(select, "checkpoints")) == checkpoints
    assert json.loads(flag(select, "evals")) == [f"{x.output}/eval.json" for x in validations]
    assert flag(s["sweep_before"], "policy.path") == f"train/selected/{PRETRAINED}"
    # The report never sees a validation run.
    assert "validation" not in " ".join(s["report"].args)


def test_validation_seeds_must_not_overlap_the_sweep_seeds(tmp_path):
    with pytest.raises(ValueError, match=r"overlap the sweep's 1000\.\.1001"):
        micro_config(tmp_path, select=SelectSettings(seed=999, n_episodes=2))
    micro_config(tmp_path, select=SelectSettings(seed=998, n_episodes=2))  # 998, 999: disjoint
    micro_config(tmp_path, select=SelectSettings(seed=1000, enabled=False))


def test_at_and_control_differ_only_in_rate(micro):
    s = by_name(plan(micro))
    at, control = s["train_at"], s["train_control"]
    assert flag(at, "phantom.rate") == "0.3" and flag(control, "phantom.rate") == "0.0"
    assert flag(at, "policy.path") == f"train/selected/{PRETRAINED}"
    differing = set(at.args) ^ set(control.args)
    assert {a.split("=")[0] for a in differing} == {"--phantom.rate", "--output_dir"}
    # The paper's recipe: the six camera attacks, intensity uniform weak..strong.
    assert json.loads(flag(at, "phantom.attacks")) == list(CAMERA_ATTACKS)
    assert flag(at, "phantom.intensity") == "random"
    assert flag(s["train_clean"], "phantom.rate") == "0"


def test_sweeps_share_seeds_and_conditions(micro):
    sweeps = [s for s in plan(micro) if s.kind == "sweep" and s.role is not None]
    for name in ("seed", "eval.n_episodes", "phantom.attacks", "phantom.intensities", "env.task"):
        assert len({flag(s, name) for s in sweeps}) == 1, name


def test_report_compares_at_with_before_and_with_control(micro):
    report = by_name(plan(micro))["report"]
    before, after = json.loads(flag(report, "before")), json.loads(flag(report, "after"))
    assert list(zip(before, after, strict=True)) == [
        ("sweeps/before/eval.json", "sweeps/after/eval.json"),
        ("sweeps/control/eval.json", "sweeps/after/eval.json"),
    ]
    assert json.loads(flag(report, "labels")) == ["before", "AT", "control"]


def calibration_set(tmp_path, kwargs=None):
    """A calibration set holding laser blinding only (as `lerobot-phantom-calibrate --out SET/<attack>` writes)."""
    folder = tmp_path / "calibration" / "laser_blinding"
    folder.mkdir(parents=True, exist_ok=True)
    payload = {"format": 1, "attack": "laser_blinding", "kwargs": kwargs or {"model": "physical"}}
    (folder / "calibrated.json").write_text(json.dumps(payload))
    return folder.parent


def test_optional_stages(tmp_path):
    calibration = calibration_set(tmp_path)
    cfg = micro_config(
        tmp_path,
        beyond=BeyondSettings(
            leave_one_out=("laser_blinding",),
            calibration=str(calibration),
            instruction_attacks=("voice_dos",),
        ),
    )
    s = by_name(plan(cfg))
    held_out = s["train_at_without_laser_blinding"]
    assert "laser_blinding" not in json.loads(flag(held_out, "phantom.attacks"))
    assert len(json.loads(flag(held_out, "phantom.attacks"))) == len(CAMERA_ATTACKS) - 1
    assert json.loads(flag(s["sweep_at_without_laser_blinding"], "phantom.attacks")) == ["laser_blinding"]
    assert flag(s["train_at_calibrated"], "phantom.calibration") == str(calibration.resolve())
    assert len(json.loads(flag(s["train_at_calibrated"], "phantom.attacks"))) == len(CAMERA_ATTACKS)
    # Sweeps cover the attacks the set calibrates: under the others both physics are the same.
    assert json.loads(flag(s["sweep_at_calibrated"], "phantom.attacks")) == ["laser_blinding"]
    for role in ("before", "after", "control", "at_calibrated"):
        sweep = s[f"sweep_{role}_calibrated_physics"]
        assert flag(sweep, "phantom.calibration") == str(calibration.resolve())
        assert json.loads(flag(sweep, "phantom.attacks")) == ["laser_blinding"]
    assert "--phantom.calibration" not in " ".join(s["sweep_at_calibrated"].args)
    assert json.loads(flag(s["train_at_instruction"], "phantom.instruction_attacks")) == ["voice_dos"]
    assert json.loads(flag(s["sweep_at_instruction"], "phantom.attacks")) == ["voice_dos"]
    report = s["report"]
    pairs = list(zip(json.loads(flag(report, "before")), json.loads(flag(report, "after")), strict=True))
    assert ("sweeps/before/eval.json", "sweeps/at_without_laser_blinding/eval.json") in pairs
    assert (
        "sweeps/before_calibrated_physics/eval.json",
        "sweeps/at_calibrated_calibrated_physics/eval.json",
    ) in pairs
    # AT under the measured physics is judged against the rate-0 control under it as well
    assert (
        "sweeps/control_calibrated_physics/eval.json",
        "sweeps/after_calibrated_physics/eval.json",
    ) in pairs
    assert json.loads(flag(report, "labels")) == [
        "before",
        "AT",
        "control",
        "AT without Laser blinding",
        "measured-physics AT",
        "AT + instruction attacks",
        "before under measured physics",
        "AT under measured physics",
        "control under measured physics",
        "measured-physics AT under measured physics",
    ]
    # Calibrated-physics sweeps are compared with each other only, never with a naive-physics sweep.
    for b, a in pairs:
        assert b.endswith("_calibrated_physics/eval.json") == a.endswith("_calibrated_physics/eval.json"), (
            b,
            a,
        )


def changed_stages(before: StudyConfig, after: StudyConfig) -> set[str]:
    old, new = fingerprints(plan(before)), fingerprints(plan(after))
    return {name for name in new if old.get(name) != new[name]}


def test_calibrated_sweeps_can_run_fewer_intensities(tmp_path):
    beyond = BeyondSettings(
        calibration=str(calibration_set(tmp_path)), calibration_intensities=("medium", "strong")
    )
    s = by_name(plan(micro_config(tmp_path, beyond=beyond)))
    for role in ("at_calibrated", "before_calibrated_physics", "at_calibrated_calibrated_physics"):
        assert json.loads(flag(s[f"sweep_{role}"], "phantom.intensities")) == ["medium", "strong"]
    assert json.loads(flag(s["sweep_before"], "phantom.intensities")) == list(
        micro_config(tmp_path).sweep.intensities
    )


def test_a_recalibration_reruns_the_calibrated_stages_only(tmp_path):
    cfg = micro_config(tmp_path, beyond=BeyondSettings(calibration=str(calibration_set(tmp_path))))
    old = fingerprints(plan(cfg))
    calibration_set(tmp_path, {"model": "physical", "gain": 2.0})
    new = fingerprints(plan(cfg))
    changed = {name for name in new if old[name] != new[name]}
    assert changed == {
        "train_at_calibrated",
        "sweep_at_calibrated",
        "sweep_before_calibrated_physics",
        "sweep_after_calibrated_physics",
        "sweep_control_calibrated_physics",
        "sweep_at_calibrated_calibrated_physics",
        "report",
    }


def test_a_changed_setting_changes_its_stage_and_the_ones_downstream_only(micro):
    more_episodes = dataclasses.replace(micro, sweep=dataclasses.replace(micro.sweep, n_episodes=3))
    assert changed_stages(micro, more_episodes) == {"sweep_before", "sweep_after", "sweep_control", "report"}
    longer_lora = dataclasses.replace(micro, lora=dataclasses.replace(micro.lora, steps=3))
    assert changed_stages(micro, longer_lora) == {
        "train_at",
        "train_control",
        "sweep_after",
        "sweep_control",
        "report",
    }
    assert changed_stages(micro, dataclasses.replace(micro, verbose=True, threads=2)) == set()


def test_fingerprint_follows_config_file_content_not_its_path(micro, tmp_path):
    copy = tmp_path / "copy.json"
    shutil.copy(micro.train.config_path, copy)
    moved = dataclasses.replace(micro, train=dataclasses.replace(micro.train, config_path=str(copy)))
    assert changed_stages(micro, moved) == set()
    copy.write_text(copy.read_text().replace('"chunk_size": 4', '"chunk_size": 2'))
    assert "train_clean" in changed_stages(micro, moved)


def make_outputs(stage: Stage, study_dir, complete=True):
    out = study_dir / stage.output
    if stage.kind == "train":
        (out / PRETRAINED).mkdir(parents=True)
        (out / PRETRAINED / "train_config.json").write_text("{}")
        if complete:
            (out / PRETRAINED / "config.json").write_text("{}")
    elif stage.kind == "sweep":
        out.mkdir(parents=True)
        (out / "eval.json").write_text(json.dumps({"metadata": {"complete": complete}}))


@pytest.mark.parametrize("kind", ["train", "sweep"])
def test_decisions(micro, tmp_path, kind):
    stage = next(s for s in plan(micro) if s.kind == kind)
    assert decide(stage, "fp", None, tmp_path) == RUN
    make_outputs(stage, tmp_path, complete=False)
    running = {"fingerprint": "fp", "status": "running"}
    assert decide(stage, "fp", running, tmp_path) == RESUME
    assert decide(stage, "other", running, tmp_path) == RUN  # settings changed: start over
    assert decide(stage, "fp", running, tmp_path, upstream_ran=True) == RUN
    done = {"fingerprint": "fp", "status": "done"}
    assert decide(stage, "fp", done, tmp_path) == RUN  # recorded done, but the outputs are not whole
    shutil.rmtree(tmp_path / stage.output)
    make_outputs(stage, tmp_path, complete=True)
    assert decide(stage, "fp", done, tmp_path) == SKIP
    assert decide(stage, "other", done, tmp_path) == RUN
    assert decide(stage, "fp", done, tmp_path, upstream_ran=True) == RUN


def test_resume_commands(micro):
    s = by_name(plan(micro))
    assert s["train_at"].resume_argv() == [
        "lerobot-phantom-train",
        f"--config_path=train/at/{PRETRAINED}/train_config.json",
        "--resume=true",
    ]
    assert s["sweep_after"].resume_argv() == [*s["sweep_after"].argv, "--resume=true"]
    with pytest.raises(ValueError, match="cannot resume"):
        s["collect"].resume_argv()


def test_bad_settings_name_the_valid_values(tmp_path):
    with pytest.raises(ValueError, match="valid attacks"):
        micro_config(tmp_path, sweep=SweepSettings(attacks=("laser",)))
    with pytest.raises(ValueError, match="camera attacks"):
        micro_config(tmp_path, lora=LoRASettings(attacks=("voice_dos",)))
    with pytest.raises(ValueError, match="voice_dos"):
        micro_config(tmp_path, beyond=BeyondSettings(instruction_attacks=("laser_blinding",)))
    with pytest.raises(ValueError, match="tiny"):
        micro_config(tmp_path, vlm=dataclasses.replace(micro_config(tmp_path).vlm, size="huge"))
    with pytest.raises(FileNotFoundError, match="not found"):
        plan(
            micro_config(
                tmp_path, train=dataclasses.replace(micro_config(tmp_path).train, config_path="no.json")
            )
        )
