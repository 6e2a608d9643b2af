"""lerobot-phantom-select-checkpoint: the rule (most clean successes, ties to the latest), the copy, and the checks
that keep an eval file from scoring the wrong checkpoint. Real rollouts feed it in tests/study/test_study_end_to_end.py."""

import json

import pytest

from lerobot_phantom.eval.select_checkpoint import SELECTED_MODEL, SelectCheckpointConfig, main, select


def candidate(root, step: int, successes: int, episodes: int = 10, complete: bool = True):
    """A checkpoint directory and the eval.json that scored it (clean + one attacked condition)."""
    checkpoint = root / "run" / "checkpoints" / f"{step:06d}" / "pretrained_model"
    checkpoint.mkdir(parents=True)
    (checkpoint / "config.json").write_text(json.dumps({"step": step}))
    (checkpoint / "model.safetensors").write_bytes(bytes([step % 256]) * 16)
    summary = [
        {"condition": "clean", "successes": successes, "episodes": episodes},
        {"condition": "laser_blinding@strong", "successes": episodes - successes, "episodes": episodes},
    ]
    report = {
        "mode": "rollout",
        "metadata": {"complete": complete, "policy": {"path": str(checkpoint)}},
        "summary": summary,
    }
    eval_path = root / "val" / f"{step:06d}" / "eval.json"
    eval_path.parent.mkdir(parents=True)
    eval_path.write_text(json.dumps(report))
    return str(eval_path), str(checkpoint)


def config(root, pairs, **changes) -> SelectCheckpointConfig:
    evals, checkpoints = zip(*pairs, strict=True)
    return SelectCheckpointConfig(
        evals=list(evals), checkpoints=list(checkpoints), output_dir=str(root / "selected"), **changes
    )


def test_the_most_successful_checkpoint_is_copied_and_every_candidate_recorded(tmp_path):
    pairs = [candidate(tmp_path, 250, 2), candidate(tmp_path, 500, 6), candidate(tmp_path, 750, 3)]
    selection = select(config(tmp_path, pairs))
    assert selection["selected"] == pairs[1][1] and selection["selected_index"] == 1
    copied = tmp_path / "selected" / SELECTED_MODEL
    assert json.loads((copied / "config.json").read_text()) == {"step": 500}
    assert (copied / "model.safetensors").read_bytes() == bytes([500 % 256]) * 16
    on_disk = json.loads((tmp_path / "selected" / "selection.json").read_text())
    assert on_disk == selection
    assert [c["successes"] for c in on_disk["candidates"]] == [2, 6, 3]
    low, high = on_disk["candidates"][1]["ci95"]
    assert low < 0.6 < high
    # The inputs are untouched.
    assert (tmp_path / "run" / "checkpoints" / "000500" / "pretrained_model" / "config.json").is_file()


def test_ties_go_to_the_latest_checkpoint_and_the_condition_can_be_chosen(tmp_path):
    pairs = [candidate(tmp_path, 250, 5), candidate(tmp_path, 500, 5), candidate(tmp_path, 750, 1)]
    assert select(config(tmp_path, pairs))["selected_index"] == 1
    attacked = select(
        SelectCheckpointConfig(
            evals=[p[0] for p in pairs],
            checkpoints=[p[1] for p in pairs],
            output_dir=str(tmp_path / "by_attack"),
            condition="laser_blinding@strong",
        )
    )
    assert attacked["selected_index"] == 2  # 9/10 under the attack


def test_mismatched_or_unfinished_inputs_are_refused(tmp_path):
    a, b = candidate(tmp_path, 250, 2), candidate(tmp_path, 500, 6)
    swapped = [(a[0], b[1]), (b[0], a[1])]
    with pytest.raises(ValueError, match="same order"):
        select(config(tmp_path, swapped))
    unfinished = candidate(tmp_path, 750, 9, complete=False)
    with pytest.raises(ValueError, match="not a finished rollout"):
        select(config(tmp_path, [a, unfinished]))
    with pytest.raises(ValueError, match="laser_blinding@strong"):
        select(config(tmp_path, [a, b], condition="em_truncation@weak"))
    with pytest.raises(ValueError, match=r"one eval\.json per checkpoint"):
        SelectCheckpointConfig(evals=[a[0]], checkpoints=[a[1], b[1]], output_dir=str(tmp_path / "x"))
    assert not (tmp_path / "selected").exists()


def test_nothing_is_overwritten(tmp_path):
    pairs = [candidate(tmp_path, 250, 2), candidate(tmp_path, 500, 6)]
    select(config(tmp_path, pairs))
    with pytest.raises(FileExistsError, match="choose another --output_dir"):
        select(config(tmp_path, pairs))
    inside = SelectCheckpointConfig(
        evals=[p[0] for p in pairs],
        checkpoints=[p[1] for p in pairs],
        output_dir=str(tmp_path / "run"),
    )
    with pytest.raises(ValueError, match="contains the candidate"):
        select(inside)


def test_cli_prints_every_candidate_and_marks_the_selected_one(tmp_path, capsys):
    pairs = [candidate(tmp_path, 250, 2), candidate(tmp_path, 500, 6)]
    main(
        [
            f"--evals={json.dumps([p[0] for p in pairs])}",
            f"--checkpoints={json.dumps([p[1] for p in pairs])}",
            f"--output_dir={tmp_path / 'cli'}",
        ]
    )
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("  ") and "20.0%" in lines[0] and "(2/10)" in lines[0]
    assert lines[1].startswith("* ") and "60.0%" in lines[1]
    assert lines[2].endswith(str(tmp_path / "cli" / SELECTED_MODEL))
