"""``lerobot-phantom-report``: eval.json files -> the paper's tables (Markdown, CSV, LaTeX), figures and a summary.

    lerobot-phantom-report --inputs='[out/base/eval.json,out/at/eval.json]' --labels='[base,AT]' \\
        --before='[out/base/eval.json]' --after='[out/at/eval.json]' --output_dir=out/report

* ``robustness.{md,csv,tex}`` (Table 3): rows = clean + attack x intensity, columns = suites (x labels when several
  inputs); cells = TSR in %. ``results.csv`` has every number with its 95 % Wilson interval.
* ``per_task.{md,csv,tex}`` (when episodes ran more than one task): TSR (%) per condition and task;
  ``per_task_results.csv`` with intervals.
* ``before_after.{md,csv,tex}`` (Table 5): for each before/after pair, the after TSR with its change and an exact
  McNemar test on matched episodes (same suite, task and env seed); pairs whose seeds, env or conditions do not
  match are refused. Several pairs (e.g. AT vs before and AT vs a clean-training control) get one column group
  each, labelled "<after> vs <before>".
* ``level_costs.{md,csv,tex}`` / ``level_changes.{md,csv,tex}``: the camera attacks averaged per level (weak, medium,
  strong), paired per episode, with bootstrap intervals: their mean cost per run, and per before/after pair the change
  with the share of the loss won back (``level_costs.csv``, ``level_changes_tests.csv`` hold every number).
* ``tsr_vs_intensity.png`` (TSR against intensity per attack, voice attacks as clean vs on, Wilson bands) and
  ``before_after_heatmap.png``.
* ``summary.md``: the largest drops under attack and the largest gains/losses after training (every condition tied
  at one of the listed values is listed).

Tables and figures spell every attack out (with the paper's abbreviation) and carry a note saying what the cells
mean, so that they read without this documentation.
"""

import csv
import json
import textwrap
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lerobot_phantom.eval.level_effects import level_changes, level_costs
from lerobot_phantom.eval.results import CLEAN, EVAL_FILENAME, EVAL_FORMAT, episode_task
from lerobot_phantom.eval.stats import PairedTest, mcnemar_exact, wilson_interval
from lerobot_phantom.eval.tables import (
    Table,
    attack_title,
    condition_label,
    percent,
)
from lerobot_phantom.transforms.intensity import LEVELS, parse_intensity
from lerobot_phantom.transforms.registry import ATTACK_NAMES, CAMERA_ATTACKS

SIGNIFICANCE = 0.05
INTERVAL = "95% Wilson score interval"
ROBUSTNESS_NOTE = (
    "Cells: task success rate (TSR) in %, pooled over the suite's tasks; every condition runs the same env seeds. "
    "Intensities weak/medium/strong as in the paper; voice attacks act in full (one row each)."
)
BEFORE_AFTER_NOTE = (
    "Cells: TSR after training in %, then in parentheses the paired change after - before in percentage points "
    "(pp) on the same seeds; '0.0 (+0.0)' means 0 % success both before and after (no change, not a missing value); "
    "'-' = not evaluated; * = p < 0.05, exact McNemar test on the matched episodes."
)


@dataclass
class ReportConfig:
    # eval.json files (or directories holding one) for the robustness table; one column group per label, and files
    # sharing a label (e.g. one per suite) merge into one group. Offline (--dataset) results get their own table.
    inputs: list[str] = field(default_factory=list)
    # Column-group name per input; default: the policy checkpoint's name, else the file's parent directory.
    labels: list[str] | None = None
    # Before/after pairs for the adversarial-training table: before[i] is compared with after[i].
    before: list[str] = field(default_factory=list)
    # The after-training eval.json of each before[i] (same env, seeds and episodes).
    after: list[str] = field(default_factory=list)
    # Where tables, figures and summary.md are written.
    output_dir: str = "outputs/phantom_report"
    # Figures need matplotlib; tables do not.
    figures: bool = True


# ----------------------------------------------------------------------------------------------------------------
# loading and pooling
# ----------------------------------------------------------------------------------------------------------------
@dataclass
class EvalRun:
    path: Path
    label: str
    data: dict[str, Any]

    @property
    def offline(self) -> bool:
        return self.data["mode"] == "offline"

    @property
    def suites(self) -> list[str]:
        return list(dict.fromkeys(r["suite"] for r in self.data["results"]))

    @property
    def conditions(self) -> list[str]:
        return list(dict.fromkeys(r["condition"] for r in self.data["results"]))

    def episodes(self, condition: str, suite: str) -> dict[tuple[Any, int], bool]:
        """(task_id, seed) -> success for one condition and suite."""
        return {
            (r["task_id"], e["seed"]): bool(e["success"])
            for r in self.data["results"]
            if r["condition"] == condition and r["suite"] == suite
            for e in r["per_episode"]
        }

    def row(self, condition: str) -> dict[str, Any]:
        return next(r for r in self.data["results"] if r["condition"] == condition)


def load_eval(path: str | Path, label: str | None = None) -> EvalRun:
    path = Path(path)
    if path.is_dir():
        path = path / EVAL_FILENAME
    if not path.is_file():
        raise FileNotFoundError(f"no eval.json at {path} (write one with lerobot-phantom-eval)")
    with open(path) as f:
        data = json.load(f)
    if not isinstance(data, dict) or data.get("format") != EVAL_FORMAT:
        raise ValueError(f"{path} is not a lerobot-phantom-eval result (expected format {EVAL_FORMAT!r})")
    if data.get("mode") not in ("rollout", "offline"):
        raise ValueError(f"{path} has an unknown mode {data.get('mode')!r} (expected 'rollout' or 'offline')")
    if label is None:
        policy_path = data["metadata"].get("policy", {}).get("path")
        label = Path(policy_path).name if policy_path else path.parent.name
        if label in ("pretrained_model", ""):
            label = (
                Path(policy_path).parents[2].name
                if policy_path and len(Path(policy_path).parents) > 2
                else label
            )
    return EvalRun(path=path, label=label, data=data)


def merge_by_label(runs: list[EvalRun]) -> list[EvalRun]:
    """One column group per label: runs of one policy on different suites (one eval.json per suite) merge."""
    merged: dict[str, EvalRun] = {}
    for run in runs:
        if run.label not in merged:
            merged[run.label] = EvalRun(path=run.path, label=run.label, data={**run.data, "results": []})
        target = merged[run.label]
        overlap = set(target.suites) & set(run.suites)
        if overlap:
            raise ValueError(
                f"{run.path} repeats suite(s) {sorted(overlap)} of label {run.label!r}; give each input a distinct "
                "label (--labels) or drop the duplicate"
            )
        target.data["results"] = target.data["results"] + run.data["results"]
    return list(merged.values())


def pooled(run: EvalRun, condition: str, suite: str) -> tuple[int, int] | None:
    """(successes, episodes) of a condition pooled over a suite's tasks, or None when it was not run."""
    episodes = run.episodes(condition, suite)
    if not episodes:
        return None
    return sum(episodes.values()), len(episodes)


def condition_sort_key(condition: str) -> tuple:
    if condition == CLEAN:
        return (-1, 0.0, "")
    attack, _, level = condition.partition("@")
    order = ATTACK_NAMES.index(attack) if attack in ATTACK_NAMES else len(ATTACK_NAMES)
    if not level:
        return (order, 1.0, attack)
    low, high = parse_intensity(level)
    return (order, (low + high) / 2.0, attack)


def ordered_conditions(runs: list[EvalRun]) -> list[str]:
    every = dict.fromkeys(c for run in runs for c in run.conditions)
    return sorted(every, key=condition_sort_key)


# ----------------------------------------------------------------------------------------------------------------
# rendering
# ----------------------------------------------------------------------------------------------------------------


def robustness_table(runs: list[EvalRun]) -> Table:
    """Table 3: TSR (%) per condition (rows) and label x suite (columns)."""
    columns, groups = [], []
    for run in runs:
        groups.append((run.label if len(runs) > 1 else "", len(run.suites)))
        columns += run.suites
    rows = []
    for condition in ordered_conditions(runs):
        cells = []
        for run in runs:
            for suite in run.suites:
                counts = pooled(run, condition, suite)
                cells.append("-" if counts is None else percent(counts[0] / counts[1]))
        rows.append((condition, cells))
    return Table(groups=groups, columns=columns, rows=rows, notes=(ROBUSTNESS_NOTE,))


def task_columns(runs: list[EvalRun]) -> list[tuple[EvalRun, str, tuple]]:
    """(run, suite, task) of every task the runs' episodes recorded, in first-seen order."""
    columns = []
    for run in runs:
        for suite in run.suites:
            tasks = dict.fromkeys(
                episode_task(e) for r in run.data["results"] if r["suite"] == suite for e in r["per_episode"]
            )
            columns += [(run, suite, task) for task in tasks]
    return columns


def task_episodes(run: EvalRun, condition: str, suite: str, task: tuple) -> list[bool]:
    return [
        bool(e["success"])
        for r in run.data["results"]
        if r["condition"] == condition and r["suite"] == suite
        for e in r["per_episode"]
        if episode_task(e) == task
    ]


def per_task_table(runs: list[EvalRun]) -> tuple[Table, list[dict[str, Any]]]:
    """TSR (%) per condition (rows) and task (columns: suite: task name), with interval records."""
    columns = task_columns(runs)
    groups = [(run.label if len(runs) > 1 else "", sum(1 for c in columns if c[0] is run)) for run in runs]
    rows, records = [], []
    for condition in ordered_conditions(runs):
        cells = []
        for run, suite, task in columns:
            outcomes = task_episodes(run, condition, suite, task)
            if not outcomes:
                cells.append("-")
                continue
            successes, n = sum(outcomes), len(outcomes)
            cells.append(percent(successes / n))
            records.append(
                {
                    "label": run.label,
                    "suite": suite,
                    "task_index": task[0],
                    "task": task[1],
                    "condition": condition,
                    **rate_fields(successes, n),
                }
            )
        rows.append((condition, cells))
    note = "Cells: TSR in % per task (the goal each episode's env drew), over that task's episodes."
    table = Table(
        groups=groups, columns=[f"{suite}: {task[1]}" for _, suite, task in columns], rows=rows, notes=(note,)
    )
    return table, records


def rate_fields(successes: int, n: int) -> dict[str, Any]:
    """A success count as the record fields every results file shares: counts, TSR and its 95% Wilson interval."""
    low, high = wilson_interval(successes, n)
    return {"successes": successes, "episodes": n, "tsr": successes / n, "ci95_low": low, "ci95_high": high}


def results_rows(runs: list[EvalRun]) -> list[dict[str, Any]]:
    """Every pooled number with its interval and, for attacks, the paired test against clean on the same seeds."""
    out = []
    for run in runs:
        for suite in run.suites:
            clean = run.episodes(CLEAN, suite)
            for condition in ordered_conditions([run]):
                episodes = run.episodes(condition, suite)
                if not episodes:
                    continue
                successes, n = sum(episodes.values()), len(episodes)
                row = {
                    "label": run.label,
                    "suite": suite,
                    "condition": condition,
                    **rate_fields(successes, n),
                    "delta_vs_clean": None,
                    "p_vs_clean": None,
                }
                if condition != CLEAN and clean and set(clean) == set(episodes):
                    test = paired(clean, episodes)
                    row["delta_vs_clean"], row["p_vs_clean"] = test.delta, test.p_value
                out.append(row)
    return out


def paired(before: dict, after: dict) -> PairedTest:
    keys = sorted(before, key=str)
    return mcnemar_exact([before[k] for k in keys], [after[k] for k in keys])


def check_pair(before: EvalRun, after: EvalRun) -> None:
    """A before/after pair must be the same experiment with another policy: same env, suites, seeds, conditions."""
    problems = []
    for key in ("env", "episode_seeds"):
        b, a = before.data["metadata"].get(key), after.data["metadata"].get(key)
        if b != a:
            problems.append(f"{key} differs: {b} vs {a}")
    if before.suites != after.suites:
        problems.append(f"suites differ: {before.suites} vs {after.suites}")
    common = [c for c in before.conditions if c in after.conditions]
    if CLEAN not in common:
        problems.append("the clean control is missing from one of them")
    for condition in common:
        for suite in set(before.suites) & set(after.suites):
            b, a = set(before.episodes(condition, suite)), set(after.episodes(condition, suite))
            if b != a:
                problems.append(f"{condition} on {suite}: the (task, seed) episodes differ")
                break
    if problems:
        raise ValueError(
            f"cannot pair {before.path} (before) with {after.path} (after): "
            + "; ".join(problems)
            + ". Evaluate both with the same --env.*, --seed and --eval.n_episodes."
        )


def before_after(pairs: list[tuple[EvalRun, EvalRun]]) -> tuple[Table, list[dict[str, Any]]]:
    """Table 5: after-training TSR with the change from before; '*' marks p < 0.05 (exact McNemar)."""
    for b, a in pairs:
        check_pair(b, a)
    conditions = sorted(
        {c for b, a in pairs for c in b.conditions if c in a.conditions}, key=condition_sort_key
    )
    groups, columns, rows, records = [], [], [], []
    for b, a in pairs:
        groups.append((f"{a.label} vs {b.label}" if len(pairs) > 1 else "", len(b.suites)))
        columns += b.suites
    for condition in conditions:
        cells = []
        for b, a in pairs:
            for suite in b.suites:
                before_eps, after_eps = b.episodes(condition, suite), a.episodes(condition, suite)
                if not before_eps or not after_eps:  # e.g. a leave-one-out sweep of the held-out attack only
                    cells.append("-")
                    continue
                test = paired(before_eps, after_eps)
                tsr_before = sum(before_eps.values()) / len(before_eps)
                tsr_after = sum(after_eps.values()) / len(after_eps)
                mark = "*" if test.p_value < SIGNIFICANCE else ""
                cells.append(f"{percent(tsr_after)} ({100 * test.delta:+.1f}){mark}")
                records.append(
                    {
                        "before": b.label,
                        "after": a.label,
                        "suite": suite,
                        "condition": condition,
                        "episodes": test.pairs,
                        "tsr_before": tsr_before,
                        "tsr_after": tsr_after,
                        "delta": test.delta,
                        "gained": test.gained,
                        "lost": test.lost,
                        "p_value": test.p_value,
                    }
                )
        rows.append((condition, cells))
    compared = "; ".join(f"before = {b.label}, after = {a.label}" for b, a in pairs)
    return Table(groups=groups, columns=columns, rows=rows, notes=(BEFORE_AFTER_NOTE, compared)), records


def offline_table(runs: list[EvalRun]) -> tuple[Table, list[dict[str, Any]]]:
    """Offline mode: mean normalised action deviation (RMS z-score of attacked - clean action) per condition."""
    records = [
        {
            "label": run.label,
            "condition": r["condition"],
            "frames": r["frames"],
            "mean_normalized": r["mean_normalized"],
            "mean_l2": r["mean_l2"],
            "median_l2": r["median_l2"],
            "max_l2": r["max_l2"],
        }
        for run in runs
        for r in run.data["results"]
    ]
    value = {(r["label"], r["condition"]): r["mean_normalized"] for r in records}
    conditions = sorted({r["condition"] for r in records}, key=condition_sort_key)
    rows = [
        (c, [f"{value[(run.label, c)]:.3f}" if (run.label, c) in value else "-" for run in runs])
        for c in conditions
    ]
    note = (
        "Cells: mean action deviation attacked vs clean on recorded frames (RMS z-score, action std units)."
    )
    table = Table(
        groups=[("", len(runs))],
        columns=[run.label for run in runs],
        rows=rows,
        notes=(note,),
        unit="RMS z-score",
    )
    return table, records


def with_ties(rows: list[dict[str, Any]], value, top: int) -> list[dict[str, Any]]:
    """The rows whose ``value`` is among the ``top`` most extreme distinct values (rows pre-sorted, most extreme
    first): every row tied at a listed value is listed, so no tied condition is silently dropped."""
    kept = list(dict.fromkeys(round(value(r), 12) for r in rows))[:top]
    return [r for r in rows if round(value(r), 12) in kept]


def drop_lines(results: list[dict[str, Any]], top: int) -> list[str]:
    drops = [r for r in results if r["delta_vs_clean"] is not None and r["delta_vs_clean"] < 0]
    if not drops:
        return []
    drops.sort(key=lambda r: (r["delta_vs_clean"], r["label"], r["suite"]))
    lines = [
        "Largest drops under attack, in percentage points (pp) of TSR against the clean control on the same "
        "seeds (exact McNemar p):",
        "",
    ]
    for r in with_ties(drops, lambda r: r["delta_vs_clean"], top):
        lines.append(
            f"- {r['label']} / {r['suite']}: {condition_label(r['condition'])} "
            f"{100 * r['delta_vs_clean']:+.1f} pp (TSR {percent(r['tsr'])}%, p = {r['p_vs_clean']:.3g})"
        )
    return [*lines, ""]


def change_lines(changes: list[dict[str, Any]], top: int) -> list[str]:
    lines = []
    for title, sign in (("Largest gains after training", 1), ("Largest losses after training", -1)):
        chosen = sorted((r for r in changes if sign * r["delta"] > 0), key=lambda r: -sign * r["delta"])
        lines += [f"{title} (paired change in pp, exact McNemar on matched episodes):", ""]
        if not chosen:
            lines.append("- none")
        for r in with_ties(chosen, lambda r: r["delta"], top):
            lines.append(
                f"- {r['after']} vs {r['before']} / {r['suite']}: {condition_label(r['condition'])} "
                f"{percent(r['tsr_before'])}% -> {percent(r['tsr_after'])}% "
                f"({100 * r['delta']:+.1f} pp, p = {r['p_value']:.3g})"
            )
        lines.append("")
    return lines


def deviation_lines(deviations: list[dict[str, Any]], top: int) -> list[str]:
    if not deviations:
        return []
    lines = ["Largest action deviations on recorded frames (offline, std-normalised):", ""]
    chosen = sorted(deviations, key=lambda r: -r["mean_normalized"])
    for r in with_ties(chosen, lambda r: r["mean_normalized"], top):
        lines.append(
            f"- {r['label']}: {condition_label(r['condition'])} {r['mean_normalized']:.3f} "
            f"(mean L2 {r['mean_l2']:.3g} over {r['frames']} frames)"
        )
    return [*lines, ""]


def summary_text(
    results: list[dict[str, Any]],
    changes: list[dict[str, Any]],
    deviations: list[dict[str, Any]] = (),
    top: int = 3,
) -> str:
    """The ``top`` largest drops, gains, losses and deviations (with every condition tied at those values)."""
    body = drop_lines(results, top) + (change_lines(changes, top) if changes else [])
    body += deviation_lines(list(deviations), top)
    if not body:
        body = ["No attacked conditions to summarise."]
    return "\n".join(["# Summary", "", *body]).rstrip() + "\n"


def write_records(path: Path, records: list[dict[str, Any]]) -> None:
    if not records:
        return
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(records[0]), lineterminator="\n")
        writer.writeheader()
        writer.writerows(records)


# ----------------------------------------------------------------------------------------------------------------
# figures
# ----------------------------------------------------------------------------------------------------------------
def attack_levels(run: EvalRun, attack: str) -> list[tuple[float, str]]:
    """(x position, condition) of one attack's curve: clean at 0, then each level at its intensity midpoint; an
    all-or-nothing (voice) condition sits at 1 ("on")."""
    attacked = [c for c in run.conditions if c == attack or c.startswith(f"{attack}@")]
    points = [(0.0, CLEAN)] + [(condition_sort_key(c)[1], c) for c in attacked]
    return sorted(points)


def plot_attack_panel(ax, runs: list[EvalRun], attack: str) -> None:
    for run in runs:
        for suite in run.suites:
            xs, ys, lows, highs = [], [], [], []
            for x, condition in attack_levels(run, attack):
                counts = pooled(run, condition, suite)
                if counts is None:
                    continue
                low, high = wilson_interval(*counts)
                xs.append(x)
                ys.append(100 * counts[0] / counts[1])
                lows.append(100 * low)
                highs.append(100 * high)
            name = f"{run.label} {suite}".strip() if len(runs) > 1 else suite
            (line,) = ax.plot(xs, ys, marker="o", label=name)
            ax.fill_between(xs, lows, highs, color=line.get_color(), alpha=0.2)
    ax.set_title(attack_title(attack), fontsize=9)
    if attack in CAMERA_ATTACKS:
        ax.set_xticks([0.0, *LEVELS.values()], ["clean", *LEVELS])
    else:
        ax.set_xticks([0.0, 1.0], ["clean", "attack on"])
    ax.set_ylim(-2, 102)
    ax.grid(alpha=0.3)


def tsr_figure(runs: list[EvalRun]):
    """One panel per attack (camera attacks against intensity, voice attacks clean vs on), Wilson bands; None
    when no attack was evaluated."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    attacks = [
        a
        for a in ATTACK_NAMES
        if any(c == a or c.startswith(f"{a}@") for run in runs for c in run.conditions)
    ]
    if not attacks:
        return None
    cols = min(3, len(attacks))
    rows = (len(attacks) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3 * rows + 0.6), squeeze=False, sharey=True)
    for ax, attack in zip(axes.flat, attacks, strict=False):
        plot_attack_panel(ax, runs, attack)
    for ax in list(axes.flat)[len(attacks) :]:
        ax.axis("off")
    for row in axes:
        row[0].set_ylabel("TSR (%)")
    handles, labels = axes[0][0].get_legend_handles_labels()
    handles.append(Patch(color="grey", alpha=0.3))
    labels.append(f"shaded: {INTERVAL}")
    # Below the panels, so that it hides no curve.
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=min(4, len(labels)))
    fig.suptitle(f"Task success rate (TSR, %) under each attack; shaded bands: {INTERVAL}", fontsize=10)
    legend_rows = (len(labels) + 3) // 4
    fig.tight_layout(rect=(0, 0.05 * legend_rows + 0.02, 1, 1))
    return fig


def plot_tsr_vs_intensity(runs: list[EvalRun], path: Path) -> None:
    import matplotlib.pyplot as plt

    fig = tsr_figure(runs)
    if fig is not None:
        fig.savefig(path, dpi=120)
        plt.close(fig)


def before_after_figure(records: list[dict[str, Any]]):
    """Heatmap of the paired TSR changes (pp) per condition and comparison, '*' where p < 0.05."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    conditions = sorted({r["condition"] for r in records}, key=condition_sort_key)
    columns = list(dict.fromkeys((r["after"], r["before"], r["suite"]) for r in records))
    grid = np.full((len(conditions), len(columns)), np.nan)
    significant = np.zeros_like(grid, dtype=bool)
    for r in records:
        i, j = conditions.index(r["condition"]), columns.index((r["after"], r["before"], r["suite"]))
        grid[i, j] = 100 * r["delta"]
        significant[i, j] = r["p_value"] < SIGNIFICANCE
    limit = max(1.0, float(np.nanmax(np.abs(grid))))
    fig, ax = plt.subplots(figsize=(1.6 * len(columns) + 3.5, 0.4 * len(conditions) + 2.0))
    image = ax.imshow(grid, cmap="RdBu", vmin=-limit, vmax=limit, aspect="auto")
    for (i, j), value in np.ndenumerate(grid):
        if not np.isnan(value):
            colour = "white" if abs(value) > 0.6 * limit else "black"  # readable on the saturated ends
            mark = "*" if significant[i, j] else ""
            ax.text(j, i, f"{value:+.0f}{mark}", ha="center", va="center", fontsize=7, color=colour)
    ax.set_yticks(range(len(conditions)), [condition_label(c) for c in conditions], fontsize=7)
    # Wrapped, so that long run labels (the study's beyond-the-paper roles) do not overlap their neighbours.
    ticks = ["\n".join(textwrap.wrap(f"{a} vs {b}", 16)) + f"\n{s}" for a, b, s in columns]
    ax.set_xticks(range(len(columns)), ticks, fontsize=8)
    ax.set_title(
        f"Paired TSR change after - before (pp); * p < {SIGNIFICANCE}, exact McNemar on matched seeds",
        fontsize=9,
    )
    fig.colorbar(image, ax=ax, label="TSR change after - before (percentage points)")
    fig.tight_layout()
    return fig


def plot_before_after(records: list[dict[str, Any]], path: Path) -> None:
    import matplotlib.pyplot as plt

    fig = before_after_figure(records)
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ----------------------------------------------------------------------------------------------------------------
# entry points
# ----------------------------------------------------------------------------------------------------------------
def load_inputs(
    paths: list, labels: list[str] | None, before: list, after: list
) -> tuple[list[EvalRun], list[EvalRun], list[tuple[EvalRun, EvalRun]]]:
    """(rollout runs merged by label, offline runs, before/after pairs) with every input checked."""
    if not paths and not before:
        raise ValueError("nothing to report: give --inputs and/or --before/--after eval.json files")
    if labels is not None and len(labels) != len(paths):
        raise ValueError(f"--labels needs one label per input ({len(paths)}), got {len(labels)}")
    if len(before) != len(after):
        raise ValueError(f"--before and --after pair up one to one, got {len(before)} and {len(after)} files")
    loaded = [load_eval(p, None if labels is None else labels[i]) for i, p in enumerate(paths)]
    label_of = {r.path.resolve(): r.label for r in loaded}
    offline = [r for r in loaded if r.offline]
    if len({r.label for r in offline}) != len(offline):
        raise ValueError(
            f"offline inputs need distinct labels, got {[r.label for r in offline]}; pass --labels"
        )
    runs = merge_by_label([r for r in loaded if not r.offline])
    pairs = []
    for b, a in zip(before, after, strict=True):
        run_b, run_a = load_eval(b), load_eval(a)
        if run_b.offline or run_a.offline:
            raise ValueError("--before/--after compare task success; offline (--dataset) results have none")
        run_b.label = label_of.get(run_b.path.resolve(), run_b.label)
        run_a.label = label_of.get(run_a.path.resolve(), run_a.label)
        pairs.append((run_b, run_a))

    return runs, offline, pairs


def make_report(
    paths: list[str | Path],
    out_dir: str | Path,
    *,
    labels: list[str] | None = None,
    before: list[str | Path] | None = None,
    after: list[str | Path] | None = None,
    figures: bool = True,
) -> dict[str, Path]:
    """Write every table, figure and the summary to ``out_dir``; returns {artefact name: path}."""
    runs, offline, pairs = load_inputs(paths, labels, list(before or []), list(after or []))
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    writer = ReportWriter(out)
    results: list[dict[str, Any]] = []
    if runs:
        writer.table("robustness", robustness_table(runs))
        results = results_rows(runs)
        writer.records("results.csv", results)
        table, costs = level_costs(runs)
        writer.table("level_costs", table)
        writer.records("level_costs.csv", costs)
        if any(len({c[2] for c in task_columns([run])}) > 1 for run in runs):
            table, per_task = per_task_table(runs)
            writer.table("per_task", table)
            writer.records("per_task_results.csv", per_task)
        if figures:
            writer.figure("tsr_vs_intensity.png", plot_tsr_vs_intensity, runs)
    changes: list[dict[str, Any]] = []
    if pairs:
        table, changes = before_after(pairs)
        writer.table("before_after", table)
        writer.records("before_after_tests.csv", changes)
        table, level_records = level_changes(pairs)
        writer.table("level_changes", table)
        writer.records("level_changes_tests.csv", level_records)
        if figures:
            writer.figure("before_after_heatmap.png", plot_before_after, changes)
    deviations: list[dict[str, Any]] = []
    if offline:
        table, deviations = offline_table(offline)
        writer.table("offline", table)
        writer.records("offline_results.csv", deviations)
    writer.text("summary.md", summary_text(results, changes, deviations))
    return writer.written


@dataclass
class ReportWriter:
    """Writes the report's files into ``out`` and remembers them ({name: path})."""

    out: Path
    written: dict[str, Path] = field(default_factory=dict)

    def text(self, name: str, text: str) -> None:
        (self.out / name).write_text(text)
        self.written[name] = self.out / name

    def table(self, stem: str, table: Table) -> None:
        """``<stem>.md``, ``<stem>.csv`` and ``<stem>.tex`` of one table."""
        for suffix, text in (("md", table.markdown()), ("csv", table.csv()), ("tex", table.latex())):
            self.text(f"{stem}.{suffix}", text)

    def records(self, name: str, records: list[dict[str, Any]]) -> None:
        if records:
            write_records(self.out / name, records)
            self.written[name] = self.out / name

    def figure(self, name: str, plot, data) -> None:
        plot(data, self.out / name)
        if (self.out / name).is_file():
            self.written[name] = self.out / name


def report_cli(cfg: ReportConfig) -> dict[str, Path]:
    written = make_report(
        cfg.inputs, cfg.output_dir, labels=cfg.labels, before=cfg.before, after=cfg.after, figures=cfg.figures
    )
    for name in ("robustness.md", "before_after.md", "summary.md"):
        if name in written:
            print(written[name].read_text())
    print(f"wrote {len(written)} files to {cfg.output_dir}")
    return written


def main() -> None:
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    import draccus

    draccus.wrap()(report_cli)()


if __name__ == "__main__":
    main()
