"""A microscopic study with the real stages (tiny SmolVLA, 2 demos, 2 training steps, 2 conditions x 2 episodes):
every stage runs, a second invocation skips every stage, and the manifest and report are complete."""

import dataclasses
import io
import json

import pytest

from lerobot_phantom.study.cli import MANIFEST, Study, run_study, run_subprocess
from lerobot_phantom.study.stages import plan

pytestmark = pytest.mark.slow  # ~1-2 min on 2 shared cores: the whole loop in one process


def test_micro_study_runs_every_stage_then_skips_them_all(micro):
    study_dir = micro.output_dir
    manifest = run_study(micro)
    names = [s.name for s in plan(micro)]
    assert manifest["last_invocation"] == dict.fromkeys(names, "run")
    assert all(manifest["stages"][n]["status"] == "done" for n in names)

    from pathlib import Path

    study_dir = Path(study_dir)
    for role, path in manifest["results"].items():
        data = json.loads((study_dir / path).read_text())
        assert data["metadata"]["complete"] is True, role
        assert [r["condition"] for r in data["summary"]] == ["clean", "laser_blinding@strong"]
        for row in data["results"]:
            assert [e["seed"] for e in row["per_episode"]] == [1000, 1001]
            assert all(isinstance(e["task_index"], int) and e["instruction"] for e in row["per_episode"])
    assert set(manifest["results"]) == {"before", "after", "control"}
    assert manifest["conditions"] == {key: ["clean", "laser_blinding@strong"] for key in manifest["results"]}
    assert manifest["report"] == "report"
    # Both clean checkpoints were scored clean on the validation seeds; the sweeps ran the selected one.
    selection = json.loads((study_dir / manifest["selection"]).read_text())
    assert [c["checkpoint"] for c in selection["candidates"]] == [
        f"train/clean/checkpoints/00000{i}/pretrained_model" for i in (1, 2)
    ]
    assert all(c["episodes"] == micro.select.n_episodes for c in selection["candidates"])
    assert selection["selected"] in [c["checkpoint"] for c in selection["candidates"]]
    validation = json.loads((study_dir / selection["candidates"][0]["eval"]).read_text())
    assert [e["seed"] for e in validation["results"][0]["per_episode"]] == [5000, 5001]
    assert [r["condition"] for r in validation["summary"]] == ["clean"]
    before = json.loads((study_dir / manifest["results"]["before"]).read_text())
    assert before["metadata"]["policy"]["path"] == "train/selected/checkpoints/last/pretrained_model"
    # The AT run fine-tuned a LoRA adapter from the clean checkpoint; the control too, at rate 0.
    for name, rate in (("at", 0.3), ("control", 0.0)):
        config = json.loads(
            (study_dir / f"train/{name}/checkpoints/last/pretrained_model/train_config.json").read_text()
        )
        assert config["phantom"]["rate"] == rate
        assert config["peft"]["r"] == micro.lora.lora_rank
    report = study_dir / "report"
    for name in (
        "robustness.md",
        "before_after.md",
        "before_after.tex",
        "summary.md",
        "tsr_vs_intensity.png",
    ):
        assert (report / name).is_file(), name
    header = (report / "before_after.md").read_text().splitlines()[0]
    assert "AT vs before" in header and "AT vs control" in header

    logs = {n: (study_dir / manifest["stages"][n]["log"]).read_text() for n in names}
    again = run_study(micro)
    assert set(again["last_invocation"].values()) == {"skip"}
    assert {n: (study_dir / again["stages"][n]["log"]).read_text() for n in names} == logs
    assert json.loads((study_dir / MANIFEST).read_text())["results"] == manifest["results"]

    # One stage's setting changed: that stage and the ones after it would run, nothing else.
    changed = dataclasses.replace(micro, sweep=dataclasses.replace(micro.sweep, n_episodes=3))
    decisions = Study(changed, ["test"]).decisions()
    assert {n for n, d in decisions.items() if d == "run"} == {
        "sweep_before",
        "sweep_after",
        "sweep_control",
        "report",
    }
    assert {d for n, d in decisions.items() if not n.startswith(("sweep", "report"))} == {"skip"}


def test_subprocess_runner_runs_the_console_command_in_the_study_dir(micro, tmp_path):
    stage = next(s for s in plan(micro) if s.name == "vlm")
    log = io.BytesIO()
    log.name = "vlm.log"
    run_subprocess(stage.argv, tmp_path, log, dataclasses.replace(micro, verbose=False))
    assert (tmp_path / "vlm" / "config.json").is_file()
    assert b"wrote" in log.getvalue()
    with pytest.raises(RuntimeError, match=r"failed \(exit"):
        run_subprocess(stage.argv, tmp_path, log, dataclasses.replace(micro, verbose=False))  # out exists
