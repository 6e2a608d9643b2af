"""Study invocations with a stand-in runner (writes each stage's outputs instantly): manifest, skip, re-run of
changed stages, resume of interrupted training and sweeps. The real stages run in test_study_end_to_end.py."""

import dataclasses
import json

import pytest

from lerobot_phantom.study.cli import MANIFEST, main, run_study
from lerobot_phantom.study.stages import PRETRAINED, plan


class FakeRunner:
    """Writes what each stage's CLI would write; can fail one stage once after writing part of its outputs."""

    def __init__(self, cfg, fail: str | None = None):
        self.stages = plan(cfg)
        self.calls: list[list[str]] = []
        self.fail = fail

    def stage_of(self, argv):
        return next(
            s for s in self.stages if argv in (s.argv, s.kind in ("train", "sweep") and s.resume_argv())
        )

    def __call__(self, argv, study_dir, log, cfg):
        self.calls.append(argv)
        stage = self.stage_of(argv)
        out = study_dir / stage.output
        out.mkdir(parents=True, exist_ok=True)
        interrupted = stage.name == self.fail
        if stage.kind == "train":
            (out / PRETRAINED).mkdir(parents=True, exist_ok=True)
            (out / PRETRAINED / "train_config.json").write_text("{}")
            if not interrupted:
                (out / PRETRAINED / "config.json").write_text("{}")
        elif stage.kind == "sweep":
            metadata = {"complete": not interrupted, "conditions": ["clean", "laser_blinding@strong"]}
            (out / "eval.json").write_text(json.dumps({"metadata": metadata}))
        elif stage.kind == "collect":
            (out / "meta").mkdir()
            (out / "meta" / "info.json").write_text("{}")
        elif stage.kind == "vlm":
            (out / "config.json").write_text("{}")
        elif stage.kind == "select":
            (out / PRETRAINED).mkdir(parents=True, exist_ok=True)
            (out / PRETRAINED / "config.json").write_text("{}")
            (out / "selection.json").write_text('{"selected": "train/clean/checkpoints/000002"}')
        else:
            (out / "summary.md").write_text("# Summary\n")
        if interrupted:
            self.fail = None
            raise KeyboardInterrupt(f"interrupted {stage.name}")


def ran(runner):
    return [runner.stage_of(argv).name for argv in runner.calls]


def test_manifest_records_every_stage_and_maps_roles_to_relative_eval_files(micro):
    runner = FakeRunner(micro)
    manifest = run_study(micro, runner=runner)
    names = [s.name for s in plan(micro)]
    assert ran(runner) == names
    on_disk = json.loads((micro_dir(micro) / MANIFEST).read_text())
    assert on_disk == manifest
    assert manifest["format"] == "lerobot_phantom.study/1"
    assert manifest["command"][0] == "lerobot-phantom-study"
    assert manifest["config"]["sweep"]["n_episodes"] == micro.sweep.n_episodes
    assert manifest["seeds"]["sweep_env_seeds"] == [micro.sweep.seed, micro.sweep.seed + 1]
    assert set(manifest["versions"]) >= {"lerobot", "lerobot_phantom", "torch", "python"}
    assert "git_commit" in manifest
    assert manifest["last_invocation"] == dict.fromkeys(names, "run")
    for name in names:
        record = manifest["stages"][name]
        assert record["status"] == "done"
        assert record["argv"][0].startswith("lerobot-phantom-")
        assert record["wall_s"] >= 0 and len(record["fingerprint"]) == 16
        assert (micro_dir(micro) / record["log"]).is_file()
        # each run of a stage names the code that ran it (a resumed study may span commits)
        assert [run["git_commit"] for run in record["runs"]] == [manifest["git_commit"]]
        assert record["runs"][0]["started"] >= manifest["started"]
    assert manifest["results"] == {
        "before": "sweeps/before/eval.json",
        "after": "sweeps/after/eval.json",
        "control": "sweeps/control/eval.json",
    }
    for path in manifest["results"].values():
        assert (micro_dir(micro) / path).is_file()
    assert manifest["conditions"]["after"] == ["clean", "laser_blinding@strong"]
    assert manifest["report"] == "report"
    assert manifest["selection"] == "train/selected/selection.json"
    # The recorded command re-reads the config the study wrote.
    saved = json.loads((micro_dir(micro) / "study_config.json").read_text())
    assert saved["lora"]["steps"] == micro.lora.steps


def micro_dir(cfg):
    from pathlib import Path

    return Path(cfg.output_dir)


def test_second_invocation_skips_everything_and_a_changed_setting_reruns_downstream_only(micro):
    run_study(micro, runner=FakeRunner(micro))
    again = FakeRunner(micro)
    manifest = run_study(micro, runner=again)
    assert again.calls == []
    assert set(manifest["last_invocation"].values()) == {"skip"}
    changed = dataclasses.replace(micro, sweep=dataclasses.replace(micro.sweep, seed=2000))
    third = FakeRunner(changed)
    manifest = run_study(changed, runner=third)
    assert ran(third) == ["sweep_before", "sweep_after", "sweep_control", "report"]
    assert manifest["last_invocation"]["train_at"] == "skip"


@pytest.mark.parametrize("interrupted", ["train_at", "sweep_after"])
def test_an_interrupted_stage_resumes_and_the_stages_after_it_run(micro, interrupted):
    first = FakeRunner(micro, fail=interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_study(micro, runner=first)
    manifest = json.loads((micro_dir(micro) / MANIFEST).read_text())
    assert manifest["stages"][interrupted]["status"] == "running"
    second = FakeRunner(micro)
    manifest = run_study(micro, runner=second)
    assert manifest["last_invocation"][interrupted] == "resume"
    stage = next(s for s in plan(micro) if s.name == interrupted)
    assert second.calls[0] == stage.resume_argv()
    assert [a["action"] for a in manifest["stages"][interrupted]["runs"]] == ["run", "resume"]
    names = [s.name for s in plan(micro)]
    # Stages finished before the interruption are skipped; the interrupted one and all after it run.
    assert ran(second) == names[names.index(interrupted) :]
    assert manifest["stages"]["report"]["status"] == "done"


def test_dry_run_prints_decisions_without_running(micro, capsys):
    run_study(micro, runner=FakeRunner(micro))
    args = [
        f"--config_path={micro_dir(micro) / 'study_config.json'}",
        "--dry_run=true",
        "--sweep.n_episodes=3",
    ]
    main(args)
    lines = dict(reversed(line.split()) for line in capsys.readouterr().out.splitlines())
    assert lines["train_clean"] == "skip" and lines["sweep_before"] == "run" and lines["report"] == "run"


def _tree(root):
    return {p.relative_to(root): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_publish_copies_the_finished_results_with_paths_valid_relative_to_the_copy(micro, tmp_path):
    run_study(micro, runner=FakeRunner(micro))
    study_dir = tmp_path / "study"
    before = _tree(study_dir)
    destination = tmp_path / "docs" / "study"
    main([f"--output_dir={study_dir}", f"--publish_to={destination}"])

    assert _tree(study_dir) == before  # the study itself is never written to
    published = json.loads((destination / MANIFEST).read_text())
    assert set(published["results"]) == {"before", "after", "control"}
    for path in published["results"].values():
        assert (destination / path).read_bytes() == (study_dir / path).read_bytes()
    assert (destination / published["report"] / "summary.md").is_file()
    for record in published["stages"].values():
        assert (destination / record["log"]).is_file()
    assert (destination / "train" / "clean" / PRETRAINED / "train_config.json").is_file()
    assert (destination / published["selection"]).read_bytes() == (
        study_dir / published["selection"]
    ).read_bytes()
    assert (destination / "sweeps" / "validation" / "000002" / "eval.json").is_file()
    assert not (destination / "train" / "selected" / PRETRAINED).exists()
    # Data, VLM and checkpoints (weights) stay behind.
    assert not (destination / "data").exists() and not (destination / "vlm").exists()
    assert not (destination / "train" / "clean" / PRETRAINED / "config.json").exists()
    assert published["published"]["stages"] == sorted(published["stages"])


def test_published_logs_keep_each_progress_bar_at_its_final_state():
    from lerobot_phantom.study.cli import final_progress_states

    log = b"$ lerobot-phantom-eval\nstep  10%\rstep  50%\rstep 100%\nwrote eval.json\r\n\rdone\n"
    assert final_progress_states(log) == b"$ lerobot-phantom-eval\nstep 100%\nwrote eval.json\ndone\n"
    assert final_progress_states(b"no bars\n") == b"no bars\n"
    # tqdm's nested bar: newline, carriage return, the bar, cursor up; redrawn on the same line each time.
    nested = b"outer 0%\n\rinner 1/3\x1b[A\n\rinner 2/3\x1b[A\n\rinner 3/3\x1b[A\router 100%\nresult table\n"
    assert final_progress_states(nested) == b"outer 100%\nresult table\n"  # as the terminal shows it


def test_publish_leaves_out_an_unfinished_sweep(micro, tmp_path):
    with pytest.raises(KeyboardInterrupt):
        run_study(micro, runner=FakeRunner(micro, fail="sweep_after"))
    destination = tmp_path / "published"
    main([f"--output_dir={tmp_path / 'study'}", f"--publish_to={destination}"])
    published = json.loads((destination / MANIFEST).read_text())
    assert set(published["results"]) == {"before"}
    assert "sweep_after" not in published["published"]["stages"]
    assert not (destination / "sweeps" / "after").exists()


def test_publish_refuses_the_study_dir_and_a_foreign_non_empty_dir(micro, tmp_path):
    run_study(micro, runner=FakeRunner(micro))
    study_dir = tmp_path / "study"
    with pytest.raises(ValueError, match="outside the study directory"):
        main([f"--output_dir={study_dir}", f"--publish_to={study_dir / 'docs'}"])
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    with pytest.raises(FileExistsError, match="choose another directory"):
        main([f"--output_dir={study_dir}", f"--publish_to={foreign}"])
    assert (foreign / "notes.txt").read_text() == "mine"
    with pytest.raises(FileNotFoundError, match="nothing to publish"):
        main([f"--output_dir={tmp_path / 'empty'}", f"--publish_to={tmp_path / 'out'}"])


class TimedRunner(FakeRunner):
    """FakeRunner that takes a moment per stage and records when each stage started and ended."""

    def __init__(self, cfg, fail=None):
        super().__init__(cfg, fail)
        self.spans: dict[str, tuple[float, float]] = {}

    def __call__(self, argv, study_dir, log, cfg):
        import time

        start = time.monotonic()
        time.sleep(0.05)
        try:
            super().__call__(argv, study_dir, log, cfg)
        finally:
            self.spans[self.stage_of(argv).name] = (start, time.monotonic())


def test_jobs_run_independent_stages_side_by_side_after_their_dependencies(micro):
    sequential = run_study(micro, runner=FakeRunner(micro))
    parallel_cfg = dataclasses.replace(micro, output_dir=micro.output_dir + "_jobs", jobs=2, in_process=False)
    runner = TimedRunner(parallel_cfg)
    manifest = run_study(parallel_cfg, runner=runner)
    stages = plan(parallel_cfg)
    assert set(runner.spans) == {s.name for s in stages}
    assert {k: r["status"] for k, r in manifest["stages"].items()} == {
        k: r["status"] for k, r in sequential["stages"].items()
    }
    assert manifest["results"] == sequential["results"]
    for stage in stages:  # nothing starts before what it depends on has ended
        for dependency in stage.depends:
            assert runner.spans[dependency][1] <= runner.spans[stage.name][0], (dependency, stage.name)
    before, at = runner.spans["sweep_before"], runner.spans["train_at"]
    assert before[0] < at[1] and at[0] < before[1]  # both wait only for the selection: they ran side by side
    assert (
        max(  # never more than two at once
            sum(1 for s, e in runner.spans.values() if s <= t < e) for t, _ in runner.spans.values()
        )
        <= 2
    )
    again = FakeRunner(parallel_cfg)
    assert set(run_study(parallel_cfg, runner=again)["last_invocation"].values()) == {"skip"}
    assert again.calls == []


def test_jobs_a_failing_stage_lets_the_running_one_finish_then_resumes(micro):
    cfg = dataclasses.replace(micro, jobs=2, in_process=False)
    first = TimedRunner(cfg, fail="train_at")
    with pytest.raises(KeyboardInterrupt):
        run_study(cfg, runner=first)
    manifest = json.loads((micro_dir(cfg) / MANIFEST).read_text())
    assert manifest["stages"]["train_at"]["status"] == "running"
    assert manifest["stages"]["sweep_before"]["status"] == "done"  # started beside it, finished and recorded
    assert "sweep_after" not in manifest["stages"] and "report" not in manifest["stages"]
    second = FakeRunner(cfg)
    manifest = run_study(cfg, runner=second)
    assert manifest["last_invocation"]["train_at"] == "resume"
    assert manifest["last_invocation"]["sweep_before"] == "skip"
    assert manifest["stages"]["report"]["status"] == "done"


def test_jobs_must_be_positive_and_run_subprocesses(tmp_path):
    from lerobot_phantom.study.config import StudyConfig

    with pytest.raises(ValueError, match="--jobs must be >= 1"):
        StudyConfig(output_dir=str(tmp_path), jobs=0)
    with pytest.raises(ValueError, match="in_process"):
        StudyConfig(output_dir=str(tmp_path), jobs=2, in_process=True)
