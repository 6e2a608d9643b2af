"""Camera attacks averaged per level, paired per episode (``eval/level_effects.py``)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lerobot_phantom.eval.level_effects import level_changes, level_costs
from lerobot_phantom.eval.report import load_eval, make_report
from lerobot_phantom.eval.results import EVAL_FORMAT, pooled_summary, summarize

ATTACKS = ("laser_blinding", "em_color_strip", "ultrasound_blur")


def outcomes(rng: np.random.Generator, episodes: int, p_clean: float, p_attacked: dict[str, float]) -> dict:
    """condition -> success array; attacked conditions for every attack at each level in ``p_attacked``."""
    out = {"clean": rng.random(episodes) < p_clean}
    for level, p in p_attacked.items():
        for attack in ATTACKS:
            out[f"{attack}@{level}"] = rng.random(episodes) < p
    return out


def write_eval(path, successes: dict, seeds: list[int]):
    results = []
    for condition, bits in successes.items():
        attack, _, level = condition.partition("@")
        per_episode = [{"seed": s, "success": bool(b)} for s, b in zip(seeds, bits, strict=True)]
        results.append(
            {
                "condition": condition,
                "attack": attack,
                "intensity": level or None,
                "suite": "goal",
                "task_id": 0,
                **summarize(per_episode),
                "per_episode": per_episode,
            }
        )
    data = {
        "format": EVAL_FORMAT,
        "mode": "rollout",
        "metadata": {"env": {"type": "phantom_table", "task": "goal"}, "episode_seeds": list(seeds)},
        "results": results,
        "summary": pooled_summary(results),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data))
    return load_eval(path, path.parent.name)


def test_mean_cost_is_the_paired_per_episode_average_with_an_interval_over_episodes(tmp_path):
    rng = np.random.default_rng(11)
    episodes = 200
    successes = outcomes(rng, episodes, 0.7, {"medium": 0.4, "strong": 0.1})
    run = write_eval(tmp_path / "before" / "eval.json", successes, list(range(episodes)))
    table, records = level_costs([run])
    by_level = {r["level"]: r for r in records}
    assert set(by_level) == {"medium", "strong"}  # weak was not evaluated
    for level in ("medium", "strong"):
        attacked = np.mean([successes[f"{a}@{level}"] for a in ATTACKS], axis=0)
        per_episode = successes["clean"] - attacked
        record = by_level[level]
        assert record["attacks"] == len(ATTACKS) and record["episodes"] == episodes
        assert record["drop"] == pytest.approx(per_episode.mean())
        # the interval resamples episodes: about +-1.96 standard errors of the per-episode differences
        half_width = (record["ci_high"] - record["ci_low"]) / 2
        assert half_width == pytest.approx(1.96 * per_episode.std(ddof=1) / np.sqrt(episodes), rel=0.15)
        assert record["ci_low"] < record["drop"] < record["ci_high"]
    rows = dict(table.rows)
    assert rows["camera attacks, weak"] == ["-"]
    assert rows["camera attacks, strong"][0].startswith(f"{100 * by_level['strong']['drop']:+.1f} [")
    assert rows["camera attacks, strong"][0].endswith(
        "(3 of 6 attacks)"
    )  # an average over fewer than all six


def test_change_and_share_won_back_against_the_drop_before(tmp_path):
    rng = np.random.default_rng(12)
    episodes, seeds = 120, list(range(120))
    before = outcomes(rng, episodes, 0.8, {"medium": 0.2})
    # after training: the clean episodes unchanged, every attacked episode succeeds exactly when clean did
    after = dict.fromkeys(before, before["clean"])
    table, records = level_changes(
        [
            (
                write_eval(tmp_path / "before" / "eval.json", before, seeds),
                write_eval(tmp_path / "after" / "eval.json", after, seeds),
            )
        ]
    )
    by_level = {r["level"]: r for r in records}
    assert (
        by_level["clean"]["change"] == 0 and by_level["clean"]["ci_low"] == by_level["clean"]["ci_high"] == 0
    )
    medium = by_level["medium"]
    drop = np.mean(before["clean"] - np.mean([before[f"{a}@medium"] for a in ATTACKS], axis=0))
    assert medium["drop_before"] == pytest.approx(drop) and drop > 0.4
    assert medium["change"] == pytest.approx(drop)  # the whole loss won back
    assert medium["share_recovered"] == pytest.approx(1.0)
    assert dict(table.rows)["camera attacks, medium"][0].endswith(
        f"of {100 * drop:.1f} (100%) (3 of 6 attacks)"
    )


def test_identical_policies_change_nothing(tmp_path):
    rng = np.random.default_rng(13)
    seeds = list(range(60))
    same = outcomes(rng, 60, 0.5, {"weak": 0.4, "strong": 0.2})
    a = write_eval(tmp_path / "a" / "eval.json", same, seeds)
    b = write_eval(tmp_path / "b" / "eval.json", same, seeds)
    _, records = level_changes([(a, b)])
    assert [r["level"] for r in records] == ["clean", "weak", "strong"]
    assert all(r["change"] == r["ci_low"] == r["ci_high"] == 0 for r in records)


def test_a_sweep_of_fewer_attacks_is_not_averaged_against_all_of_them(tmp_path):
    rng = np.random.default_rng(14)
    seeds = list(range(40))
    full = outcomes(rng, 40, 0.6, {"medium": 0.3})
    held_out = {c: v for c, v in full.items() if c in ("clean", "laser_blinding@medium")}
    table, records = level_changes(
        [
            (
                write_eval(tmp_path / "b" / "eval.json", full, seeds),
                write_eval(tmp_path / "a" / "eval.json", held_out, seeds),
            )
        ]
    )
    assert dict(table.rows)["camera attacks, medium"] == ["-"]
    assert [r["level"] for r in records] == ["clean"]


def test_an_attack_run_on_other_episodes_than_clean_is_refused(tmp_path):
    rng = np.random.default_rng(15)
    successes = outcomes(rng, 30, 0.6, {"medium": 0.3})
    run = write_eval(tmp_path / "r" / "eval.json", successes, list(range(30)))
    for result in run.data["results"]:
        if result["condition"] == "em_color_strip@medium":
            result["per_episode"][0]["seed"] = 999
    with pytest.raises(ValueError, match="em_color_strip@medium on goal ran other episodes"):
        level_costs([run])


def test_the_report_writes_both_level_tables(tmp_path):
    rng = np.random.default_rng(16)
    seeds = list(range(50))
    before = write_eval(tmp_path / "before" / "eval.json", outcomes(rng, 50, 0.6, {"medium": 0.3}), seeds)
    after = write_eval(tmp_path / "after" / "eval.json", outcomes(rng, 50, 0.6, {"medium": 0.5}), seeds)
    written = make_report(
        [before.path, after.path],
        tmp_path / "report",
        before=[before.path],
        after=[after.path],
        figures=False,
    )
    for name in ("level_costs.md", "level_costs.csv", "level_changes.md", "level_changes_tests.csv"):
        assert name in written
    assert "paired percentile bootstrap" in written["level_changes.md"].read_text()
    assert (
        written["level_costs.csv"].read_text().splitlines()[0].startswith("run,suite,level,attacks,episodes")
    )
