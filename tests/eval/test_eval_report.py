"""lerobot-phantom-report: tables rendered from fixture eval.json files (written here) match exactly."""

import json

import pytest

from lerobot_phantom.eval.report import (
    BEFORE_AFTER_NOTE,
    INTERVAL,
    ROBUSTNESS_NOTE,
    ReportConfig,
    before_after_figure,
    make_report,
    report_cli,
    summary_text,
    tsr_figure,
)
from lerobot_phantom.eval.results import EVAL_FORMAT, pooled_summary, summarize
from lerobot_phantom.eval.tables import ABBREVIATIONS, ATTACK_TITLES

SEEDS = [0, 1, 2, 3, 4, 5]
BASE = {
    ("clean", "spatial"): "111111",
    ("clean", "goal"): "111100",
    ("laser_blinding@weak", "spatial"): "111100",
    ("laser_blinding@weak", "goal"): "101000",
    ("laser_blinding@strong", "spatial"): "000000",
    ("laser_blinding@strong", "goal"): "000000",
    ("voice_dos", "spatial"): "110111",
    ("voice_dos", "goal"): "000000",
}
TRAINED = {
    ("clean", "spatial"): "111111",
    ("clean", "goal"): "110100",
    ("laser_blinding@weak", "spatial"): "111111",
    ("laser_blinding@weak", "goal"): "111000",
    ("laser_blinding@strong", "spatial"): "111111",
    ("laser_blinding@strong", "goal"): "100000",
    ("voice_dos", "spatial"): "110111",
    ("voice_dos", "goal"): "000000",
}


def write_eval(path, outcomes, seeds=SEEDS, env_task="all"):
    results = []
    for (condition, suite), bits in outcomes.items():
        attack, _, level = condition.partition("@")
        per_episode = [{"seed": s, "success": b == "1"} for s, b in zip(seeds, bits, strict=True)]
        results.append(
            {
                "condition": condition,
                "attack": attack,
                "intensity": level or None,
                "suite": suite,
                "task_id": 0,
                **summarize(per_episode),
                "per_episode": per_episode,
            }
        )
    data = {
        "format": EVAL_FORMAT,
        "mode": "rollout",
        "metadata": {
            "policy": {"path": None, "type": "test"},
            "env": {"type": "phantom_table", "task": env_task},
            "episode_seeds": list(seeds),
        },
        "results": results,
        "summary": pooled_summary(results),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data))
    return path


@pytest.fixture
def evals(tmp_path):
    return write_eval(tmp_path / "base" / "eval.json", BASE), write_eval(
        tmp_path / "at" / "eval.json", TRAINED
    )


def test_robustness_and_before_after_tables_match_exactly(evals, tmp_path):
    base, trained = evals
    out = tmp_path / "report"
    written = make_report(
        [base, trained], out, labels=["base", "AT"], before=[base], after=[trained], figures=False
    )
    assert (out / "robustness.md").read_text() == (
        "| Attack | base spatial | base goal | AT spatial | AT goal |\n"
        "|---|---:|---:|---:|---:|\n"
        "| Clean | 100.0 | 66.7 | 100.0 | 50.0 |\n"
        "| Laser blinding (LB), weak | 66.7 | 33.3 | 100.0 | 50.0 |\n"
        "| Laser blinding (LB), strong | 0.0 | 0.0 | 100.0 | 16.7 |\n"
        "| Voice DoS (VD) | 83.3 | 0.0 | 83.3 | 0.0 |\n"
        "\n"
        f"{ROBUSTNESS_NOTE}\n"
    )
    assert (out / "robustness.csv").read_text() == (
        ",base,base,AT,AT\n"
        "condition [TSR %],spatial,goal,spatial,goal\n"
        "clean,100.0,66.7,100.0,50.0\n"
        "laser_blinding@weak,66.7,33.3,100.0,50.0\n"
        "laser_blinding@strong,0.0,0.0,100.0,16.7\n"
        "voice_dos,83.3,0.0,83.3,0.0\n"
    )
    assert (out / "robustness.tex").read_text() == (
        "\\begin{tabular}{lcccc}\n"
        "\\toprule\n"
        " & \\multicolumn{2}{c}{\\textbf{base}} & \\multicolumn{2}{c}{\\textbf{AT}} \\\\\n"
        "\\cmidrule(lr){2-3} \\cmidrule(lr){4-5}\n"
        "\\textbf{Attack} & spatial & goal & spatial & goal \\\\\n"
        "\\midrule\n"
        "\\textbf{Clean} & 100.0 & 66.7 & 100.0 & 50.0 \\\\\n"
        "\\midrule\n"
        "Laser blinding (LB), weak & 66.7 & 33.3 & 100.0 & 50.0 \\\\\n"
        "Laser blinding (LB), strong & 0.0 & 0.0 & 100.0 & 16.7 \\\\\n"
        "Voice DoS (VD) & 83.3 & 0.0 & 83.3 & 0.0 \\\\\n"
        "\\bottomrule\n"
        + "\\multicolumn{5}{l}{\\footnotesize "
        + ROBUSTNESS_NOTE.replace("%", "\\%")
        + "} \\\\\n"
        + "\\end{tabular}\n"
    )
    # After TSR (change in points); '*' = exact McNemar p < 0.05 (6 of 6 discordant pairs: p = 2/64).
    assert (out / "before_after.md").read_text() == (
        "| Attack | spatial | goal |\n"
        "|---|---:|---:|\n"
        "| Clean | 100.0 (+0.0) | 50.0 (-16.7) |\n"
        "| Laser blinding (LB), weak | 100.0 (+33.3) | 50.0 (+16.7) |\n"
        "| Laser blinding (LB), strong | 100.0 (+100.0)* | 16.7 (+16.7) |\n"
        "| Voice DoS (VD) | 83.3 (+0.0) | 0.0 (+0.0) |\n"
        "\n"
        f"{BEFORE_AFTER_NOTE}\n"
        "\n"
        "before = base, after = AT\n"
    )
    # Every condition tied at a listed value is listed: VD on goal drops as far as LB strong on goal (-66.7 pp),
    # and LB weak / LB strong on goal gain the same +16.7 pp.
    assert (out / "summary.md").read_text() == (
        "# Summary\n"
        "\n"
        "Largest drops under attack, in percentage points (pp) of TSR against the clean control on the same seeds "
        "(exact McNemar p):\n"
        "\n"
        "- base / spatial: Laser blinding (LB), strong -100.0 pp (TSR 0.0%, p = 0.0312)\n"
        "- base / goal: Laser blinding (LB), strong -66.7 pp (TSR 0.0%, p = 0.125)\n"
        "- base / goal: Voice DoS (VD) -66.7 pp (TSR 0.0%, p = 0.125)\n"
        "- AT / goal: Voice DoS (VD) -50.0 pp (TSR 0.0%, p = 0.25)\n"
        "\n"
        "Largest gains after training (paired change in pp, exact McNemar on matched episodes):\n"
        "\n"
        "- AT vs base / spatial: Laser blinding (LB), strong 0.0% -> 100.0% (+100.0 pp, p = 0.0312)\n"
        "- AT vs base / spatial: Laser blinding (LB), weak 66.7% -> 100.0% (+33.3 pp, p = 0.5)\n"
        "- AT vs base / goal: Laser blinding (LB), weak 33.3% -> 50.0% (+16.7 pp, p = 1)\n"
        "- AT vs base / goal: Laser blinding (LB), strong 0.0% -> 16.7% (+16.7 pp, p = 1)\n"
        "\n"
        "Largest losses after training (paired change in pp, exact McNemar on matched episodes):\n"
        "\n"
        "- AT vs base / goal: Clean 66.7% -> 50.0% (-16.7 pp, p = 1)\n"
    )
    results = (out / "results.csv").read_text().splitlines()
    assert results[0].startswith("label,suite,condition,successes,episodes,tsr,ci95_low,ci95_high")
    assert len(results) == 1 + 2 * 2 * 4
    assert set(written) >= {"robustness.md", "before_after.tex", "before_after_tests.csv", "summary.md"}


def test_figures_are_written(evals, tmp_path):
    base, trained = evals
    written = make_report([base], tmp_path / "fig", before=[base], after=[trained])
    for name in ("tsr_vs_intensity.png", "before_after_heatmap.png"):
        assert written[name].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_single_input_uses_suite_columns_and_directory_label(evals, tmp_path):
    base, _ = evals
    report_cli(ReportConfig(inputs=[str(base.parent)], output_dir=str(tmp_path / "one"), figures=False))
    assert (tmp_path / "one" / "robustness.md").read_text().splitlines()[0] == "| Attack | spatial | goal |"
    assert (tmp_path / "one" / "robustness.csv").read_text().splitlines()[
        0
    ] == "condition [TSR %],spatial,goal"


def test_one_file_per_suite_merges_into_one_column_group(tmp_path):
    spatial = write_eval(tmp_path / "s" / "eval.json", {k: v for k, v in BASE.items() if k[1] == "spatial"})
    goal = write_eval(tmp_path / "g" / "eval.json", {k: v for k, v in BASE.items() if k[1] == "goal"})
    make_report([spatial, goal], tmp_path / "merged", labels=["base", "base"], figures=False)
    lines = (tmp_path / "merged" / "robustness.md").read_text().splitlines()
    assert lines[0] == "| Attack | spatial | goal |"
    assert lines[2] == "| Clean | 100.0 | 66.7 |"


def test_mismatched_pairs_are_refused(evals, tmp_path):
    base, _ = evals
    other_seeds = write_eval(tmp_path / "seeds" / "eval.json", TRAINED, seeds=[10, 11, 12, 13, 14, 15])
    with pytest.raises(ValueError, match="episode_seeds differs"):
        make_report([], tmp_path / "r1", before=[base], after=[other_seeds])
    other_env = write_eval(tmp_path / "env" / "eval.json", TRAINED, env_task="goal")
    with pytest.raises(ValueError, match="env differs"):
        make_report([], tmp_path / "r2", before=[base], after=[other_env])
    with pytest.raises(ValueError, match="pair up one to one"):
        make_report([], tmp_path / "r3", before=[base], after=[])


def test_bad_inputs_give_clear_errors(evals, tmp_path):
    base, _ = evals
    with pytest.raises(FileNotFoundError, match=r"no eval\.json"):
        make_report([tmp_path / "missing"], tmp_path / "r")
    (tmp_path / "junk.json").write_text("{}")
    with pytest.raises(ValueError, match="not a lerobot-phantom-eval result"):
        make_report([tmp_path / "junk.json"], tmp_path / "r")
    with pytest.raises(ValueError, match="repeats suite"):
        make_report([base, base], tmp_path / "r")
    with pytest.raises(ValueError, match="one label per input"):
        make_report([base], tmp_path / "r", labels=["a", "b"])


def write_offline(path, deviations):
    results = [
        {"condition": c, "frames": 4, "mean_normalized": v, "mean_l2": 2 * v, "median_l2": v, "max_l2": 3 * v}
        for c, v in deviations.items()
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        json.dumps({"format": EVAL_FORMAT, "mode": "offline", "metadata": {}, "results": results})
    )
    return path


def test_offline_results_get_their_own_table(evals, tmp_path):
    base, _ = evals
    real_a = write_offline(tmp_path / "a" / "eval.json", {"voice_dos": 0.0, "laser_blinding@strong": 1.25})
    real_b = write_offline(tmp_path / "b" / "eval.json", {"laser_blinding@strong": 0.5})
    make_report([base, real_a, real_b], tmp_path / "r", labels=["sim", "real", "real AT"], figures=False)
    assert (tmp_path / "r" / "offline.md").read_text() == (
        "| Attack | real | real AT |\n|---|---:|---:|\n| Laser blinding (LB), strong | 1.250 | 0.500 |\n"
        "| Voice DoS (VD) | 0.000 | - |\n\n"
        "Cells: mean action deviation attacked vs clean on recorded frames (RMS z-score, action std units).\n"
    )
    assert (tmp_path / "r" / "robustness.md").read_text().startswith("| Attack | spatial | goal |\n")
    assert (
        "- real: Laser blinding (LB), strong 1.250 (mean L2 2.5 over 4 frames)"
        in (tmp_path / "r" / "summary.md").read_text()
    )
    with pytest.raises(ValueError, match="offline"):
        make_report([], tmp_path / "r2", before=[real_a], after=[real_b])


def test_every_table_spells_out_each_attack_it_abbreviates(evals, tmp_path):
    base, trained = evals
    out = tmp_path / "r"
    make_report([base, trained], out, labels=["base", "AT"], before=[base], after=[trained], figures=False)
    for name in ("robustness.md", "robustness.tex", "before_after.md", "before_after.tex", "summary.md"):
        text = (out / name).read_text()
        for attack, short in ABBREVIATIONS.items():
            if attack != "clean" and f"{short})" in text:
                assert f"{ATTACK_TITLES[attack]} ({short})" in text, (name, short)
        assert "(LB)" in text, name  # the fixture's attacks are named in every table
    assert "in %" in (out / "robustness.md").read_text()
    assert "percentage points (pp)" in (out / "before_after.md").read_text()
    assert "'0.0 (+0.0)' means 0 \\% success both before and after" in (out / "before_after.tex").read_text()


def test_figures_name_the_interval_plot_voice_attacks_and_spell_out_attacks(evals):
    from lerobot_phantom.eval.report import load_eval

    base, _ = evals
    fig = tsr_figure([load_eval(base, "base")])
    titles = [ax.get_title() for ax in fig.axes if ax.get_visible() and ax.axison]
    assert titles == ["Laser blinding (LB)", "Voice DoS (VD)"]
    assert INTERVAL in fig._suptitle.get_text()
    voice = fig.axes[1]
    assert [t.get_text() for t in voice.get_xticklabels()] == ["clean", "attack on"]
    # One curve per suite with the clean and the attacked point; 83.3 % on spatial under VD.
    curves = {line.get_label(): line.get_ydata().tolist() for line in voice.get_lines()}
    assert curves["spatial"] == pytest.approx([100.0, 100 * 5 / 6])
    (legend,) = [[t.get_text() for t in legend.get_texts()] for legend in fig.legends]
    assert f"shaded: {INTERVAL}" in legend
    heatmap = before_after_figure(
        [
            {"before": "base", "after": "AT", "suite": "goal", "condition": c, "delta": d, "p_value": p}
            for c, d, p in (("clean", 0.0, 1.0), ("voice_dos", -0.5, 0.01))
        ]
    )
    ax = heatmap.axes[0]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["Clean", "Voice DoS (VD)"]
    assert "McNemar" in ax.get_title() and "pp" in ax.get_title()
    assert "-50*" in [t.get_text() for t in ax.texts]
    # Long run labels (the study's beyond-the-paper roles) wrap instead of running into their neighbours.
    long = "measured-physics AT under measured physics"
    wrapped = before_after_figure(
        [
            {
                "before": "before",
                "after": long,
                "suite": "goal",
                "condition": "clean",
                "delta": 0.1,
                "p_value": 1.0,
            }
        ]
    )
    (tick,) = [t.get_text() for t in wrapped.axes[0].get_xticklabels()]
    assert tick.replace("\n", " ") == f"{long} vs before goal"
    assert max(len(line) for line in tick.splitlines()) <= 16


def test_summary_lists_every_condition_tied_at_the_largest_drop():
    conditions = [
        "laser_blinding@strong",
        "em_truncation@strong",
        "light_projection@strong",
        "em_color_strip@strong",
    ]
    rows = [
        {
            "label": "p",
            "suite": "goal",
            "condition": c,
            "tsr": 0.0,
            "delta_vs_clean": -1.0,
            "p_vs_clean": 0.001,
        }
        for c in conditions
    ]
    rows.append({**rows[0], "condition": "ultrasound_blur@weak", "delta_vs_clean": -0.1, "tsr": 0.9})
    text = summary_text(rows, [], top=1)
    for c in conditions:
        assert f"{ATTACK_TITLES[c.split('@')[0]]} (" in text, c
    assert "Ultrasound" not in text  # the next value down is not a tie


def three_run_report(tmp_path, base, trained, third, label, before, after):
    """The report of before, AT and a third run, with the given before/after pairs; returns its directory."""
    out = tmp_path / "r"
    make_report(
        [base, trained, third],
        out,
        labels=["before", "AT", label],
        before=before,
        after=after,
        figures=False,
    )
    return out


def test_at_is_compared_with_before_and_with_the_control(evals, tmp_path):
    base, trained = evals
    control = write_eval(tmp_path / "control" / "eval.json", BASE)
    out = three_run_report(tmp_path, base, trained, control, "control", [base, control], [trained, trained])
    header = (out / "before_after.md").read_text().splitlines()[0]
    assert header == (
        "| Attack | AT vs before spatial | AT vs before goal | AT vs control spatial | AT vs control goal |"
    )
    tests = (out / "before_after_tests.csv").read_text().splitlines()
    assert len(tests) == 1 + 2 * 2 * 4


def test_a_pair_whose_after_ran_a_subset_of_the_conditions_gets_dashes(evals, tmp_path):
    # The study's beyond stages sweep a subset (the held-out attack, the instruction attacks) against the full before.
    base, trained = evals
    subset = {k: v for k, v in TRAINED.items() if k[0] in ("clean", "voice_dos")}
    held_out = write_eval(tmp_path / "held_out" / "eval.json", subset)
    out = three_run_report(tmp_path, base, trained, held_out, "held_out", [base, base], [trained, held_out])
    rows = {
        line.split(" | ")[0]: line
        for line in (out / "before_after.md").read_text().splitlines()
        if line.startswith("| ")
    }
    strong = rows["| Laser blinding (LB), strong"].split(" | ")
    assert strong[1:3] == ["100.0 (+100.0)*", "16.7 (+16.7)"] and strong[3:] == ["-", "- |"]
    assert "-" not in rows["| Voice DoS (VD)"].split(" | ")[1:]
    tests = (out / "before_after_tests.csv").read_text().splitlines()
    assert len(tests) == 1 + 2 * 4 + 2 * 2


def test_per_task_table_when_episodes_ran_several_tasks(tmp_path):
    path = write_eval(
        tmp_path / "tasks" / "eval.json", {("clean", "goal"): "110100", ("voice_dos", "goal"): "100000"}
    )
    data = json.loads(path.read_text())
    for row in data["results"]:
        for i, episode in enumerate(row["per_episode"]):
            episode.update(
                task_index=i % 2, task=["put_a", "put_b"][i % 2], instruction=f"instruction {i % 2}"
            )
    path.write_text(json.dumps(data))
    written = make_report([path], tmp_path / "r", figures=False)
    assert (tmp_path / "r" / "per_task.md").read_text().splitlines()[:4] == [
        "| Attack | goal: put_a | goal: put_b |",
        "|---|---:|---:|",
        "| Clean | 33.3 | 66.7 |",  # task a: seeds 0, 2, 4 -> 1, 0, 0; task b: 1, 3, 5 -> 1, 1, 0
        "| Voice DoS (VD) | 33.3 | 0.0 |",
    ]
    assert "per_task_results.csv" in written
    single = write_eval(tmp_path / "single" / "eval.json", BASE)
    assert "per_task.md" not in make_report([single], tmp_path / "r2", figures=False)
