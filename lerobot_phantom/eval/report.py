"""``lerobot-phantom-report``: eval.json files -> the paper's tables (Markdown, CSV, LaTeX), figures and a summary.

    lerobot-phantom-report --inputs='[out/base/eval.json,out/at/eval.json]' --labels='[base,AT]' \\
        --before='[out/base/eval.json]' --after='[out/at/eval.json]' --output_dir=out/report

* ``robustness.{md,csv,tex}`` (Table 3): rows = clean + attack x intensity, columns = suites (x labels when several
  inputs); cells = TSR in %. ``results.csv`` has every number with its 95 % Wilson interval.
* ``before_after.{md,csv,tex}`` (Table 5): for each before/after pair, the after TSR with its change and an exact
  McNemar test on matched episodes (same suite, task and env seed); pairs whose seeds, env or conditions do not
  match are refused.
* ``tsr_vs_intensity.png`` (TSR against intensity per attack, Wilson bands) and ``before_after_heatmap.png``.
* ``summary.md``: the largest drops under attack and the largest gains/losses after training.
"""

import csv
import io
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lerobot_phantom.eval.results import CLEAN, EVAL_FILENAME, EVAL_FORMAT
from lerobot_phantom.eval.stats import PairedTest, mcnemar_exact, wilson_interval
from lerobot_phantom.transforms.intensity import LEVELS, parse_intensity
from lerobot_phantom.transforms.registry import ATTACK_NAMES

ABBREVIATIONS = {
    CLEAN: "Clean",
    "laser_blinding": "LB",
    "light_projection": "LP",
    "laser_color_strip": "LCS",
    "em_color_strip": "ECS",
    "em_truncation": "ET",
    "ultrasound_blur": "UB",
    "voice_dos": "VD",
    "voice_spoofing": "VS",
}
SIGNIFICANCE = 0.05


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


def condition_label(condition: str, latex: bool = False) -> str:
    attack, _, level = condition.partition("@")
    name = ABBREVIATIONS.get(attack, attack)
    if not level:
        return f"\\textbf{{{name}}}" if latex and condition == CLEAN else name
    return f"${name}_{{{level}}}$" if latex else f"{name} {level}"


def percent(value: float) -> str:
    return f"{100.0 * value:.1f}"


# ----------------------------------------------------------------------------------------------------------------
# rendering
# ----------------------------------------------------------------------------------------------------------------
@dataclass
class Table:
    """A table with one header row per column group (labels) and one per column (suites)."""

    groups: list[tuple[str, int]]  # (group label, number of columns)
    columns: list[str]
    rows: list[tuple[str, list[str]]]  # (condition, cells)
    corner: str = "Attack"

    @property
    def column_groups(self) -> list[str]:
        """The group label of every column."""
        return [label for label, count in self.groups for _ in range(count)]

    def markdown(self) -> str:
        headers = [
            f"{group} {column}".strip()
            for group, column in zip(self.column_groups, self.columns, strict=True)
        ]
        lines = [
            "| " + " | ".join([self.corner, *headers]) + " |",
            "|" + "|".join(["---"] + ["---:"] * len(headers)) + "|",
        ]
        lines += ["| " + " | ".join([condition_label(c), *cells]) + " |" for c, cells in self.rows]
        return "\n".join(lines) + "\n"

    def csv(self) -> str:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        if any(self.column_groups):
            writer.writerow(["", *self.column_groups])
        writer.writerow(["condition", *self.columns])
        for condition, cells in self.rows:
            writer.writerow([condition, *cells])
        return buffer.getvalue()

    def latex(self) -> str:
        n = len(self.columns)
        lines = ["\\begin{tabular}{l" + "c" * n + "}", "\\toprule"]
        if any(label for label, _ in self.groups):
            spans, start = [], 2
            cells = []
            for label, count in self.groups:
                cells.append(f"\\multicolumn{{{count}}}{{c}}{{\\textbf{{{latex_escape(label)}}}}}")
                spans.append(f"\\cmidrule(lr){{{start}-{start + count - 1}}}")
                start += count
            lines.append(" & ".join(["", *cells]) + " \\\\")
            lines.append(" ".join(spans))
        lines.append(" & ".join([f"\\textbf{{{self.corner}}}", *map(latex_escape, self.columns)]) + " \\\\")
        lines.append("\\midrule")
        for condition, cells in self.rows:
            lines.append(" & ".join([condition_label(condition, latex=True), *cells]) + " \\\\")
            if condition == CLEAN:
                lines.append("\\midrule")
        lines += ["\\bottomrule", "\\end{tabular}"]
        return "\n".join(lines) + "\n"


def latex_escape(text: str) -> str:
    for char, escaped in (
        ("\\", "\\textbackslash{}"),
        ("_", "\\_"),
        ("%", "\\%"),
        ("&", "\\&"),
        ("#", "\\#"),
    ):
        text = text.replace(char, escaped)
    return text


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
    return Table(groups=groups, columns=columns, rows=rows)


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
                low, high = wilson_interval(successes, n)
                row = {
                    "label": run.label,
                    "suite": suite,
                    "condition": condition,
                    "successes": successes,
                    "episodes": n,
                    "tsr": successes / n,
                    "ci95_low": low,
                    "ci95_high": high,
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
        groups.append((a.label if len(pairs) > 1 else "", len(b.suites)))
        columns += b.suites
    for condition in conditions:
        cells = []
        for b, a in pairs:
            for suite in b.suites:
                before_eps, after_eps = b.episodes(condition, suite), a.episodes(condition, suite)
                if not before_eps:
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
    return Table(groups=groups, columns=columns, rows=rows), records


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
    return Table(groups=[("", len(runs))], columns=[run.label for run in runs], rows=rows), records


def summary_text(
    results: list[dict[str, Any]],
    changes: list[dict[str, Any]],
    deviations: list[dict[str, Any]] = (),
    top: int = 3,
) -> str:
    lines = ["# Summary", ""]
    drops = [r for r in results if r["delta_vs_clean"] is not None]
    if drops:
        lines.append("Largest drops under attack (paired with the clean control on the same seeds):")
        lines.append("")
        for r in sorted(drops, key=lambda r: (r["delta_vs_clean"], r["label"], r["suite"]))[:top]:
            lines.append(
                f"- {r['label']} / {r['suite']}: {condition_label(r['condition'])} "
                f"{100 * r['delta_vs_clean']:+.1f} pp (TSR {percent(r['tsr'])}%, p = {r['p_vs_clean']:.3g})"
            )
        lines.append("")
    if changes:
        for title, chosen in (
            ("Largest gains after training", sorted(changes, key=lambda r: -r["delta"])[:top]),
            ("Largest losses after training", sorted(changes, key=lambda r: r["delta"])[:top]),
        ):
            chosen = [r for r in chosen if (r["delta"] > 0 if "gains" in title else r["delta"] < 0)]
            lines.append(f"{title} (exact McNemar on matched episodes):")
            lines.append("")
            if not chosen:
                lines.append("- none")
            for r in chosen:
                lines.append(
                    f"- {r['after']} / {r['suite']}: {condition_label(r['condition'])} "
                    f"{percent(r['tsr_before'])}% -> {percent(r['tsr_after'])}% "
                    f"({100 * r['delta']:+.1f} pp, p = {r['p_value']:.3g})"
                )
            lines.append("")
    if deviations:
        lines.append("Largest action deviations on recorded frames (offline, std-normalised):")
        lines.append("")
        for r in sorted(deviations, key=lambda r: -r["mean_normalized"])[:top]:
            lines.append(
                f"- {r['label']}: {condition_label(r['condition'])} {r['mean_normalized']:.3f} "
                f"(mean L2 {r['mean_l2']:.3g} over {r['frames']} frames)"
            )
        lines.append("")
    if len(lines) == 2:
        lines.append("No attacked conditions to summarise.")
    return "\n".join(lines).rstrip() + "\n"


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
def plot_tsr_vs_intensity(runs: list[EvalRun], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    attacks = [a for a in ATTACK_NAMES if any(c.startswith(f"{a}@") for run in runs for c in run.conditions)]
    if not attacks:
        return
    cols = min(3, len(attacks))
    rows = (len(attacks) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3 * rows), squeeze=False, sharey=True)
    for ax, attack in zip(axes.flat, attacks, strict=False):
        for run in runs:
            for suite in run.suites:
                attacked = sorted(
                    (c for c in run.conditions if c.startswith(f"{attack}@")), key=condition_sort_key
                )
                levels = [CLEAN, *attacked]
                xs, ys, lows, highs = [], [], [], []
                for condition in levels:
                    counts = pooled(run, condition, suite)
                    if counts is None:
                        continue
                    low, high = wilson_interval(*counts)
                    xs.append(0.0 if condition == CLEAN else condition_sort_key(condition)[1])
                    ys.append(100 * counts[0] / counts[1])
                    lows.append(100 * low)
                    highs.append(100 * high)
                name = f"{run.label} {suite}".strip() if len(runs) > 1 else suite
                (line,) = ax.plot(xs, ys, marker="o", label=name)
                ax.fill_between(xs, lows, highs, color=line.get_color(), alpha=0.2)
        ax.set_title(ABBREVIATIONS.get(attack, attack))
        ax.set_xticks([0.0, *LEVELS.values()], ["clean", *LEVELS])
        ax.set_ylim(-2, 102)
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(attacks) :]:
        ax.axis("off")
    axes[0][0].set_ylabel("TSR (%)")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_before_after(records: list[dict[str, Any]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    conditions = sorted({r["condition"] for r in records}, key=condition_sort_key)
    columns = list(dict.fromkeys((r["after"], r["suite"]) for r in records))
    grid = np.full((len(conditions), len(columns)), np.nan)
    for r in records:
        grid[conditions.index(r["condition"]), columns.index((r["after"], r["suite"]))] = 100 * r["delta"]
    limit = max(1.0, float(np.nanmax(np.abs(grid))))
    fig, ax = plt.subplots(figsize=(1.2 * len(columns) + 2.5, 0.4 * len(conditions) + 1.5))
    image = ax.imshow(grid, cmap="RdBu", vmin=-limit, vmax=limit, aspect="auto")
    for (i, j), value in np.ndenumerate(grid):
        if not np.isnan(value):
            colour = "white" if abs(value) > 0.6 * limit else "black"  # readable on the saturated ends
            ax.text(j, i, f"{value:+.0f}", ha="center", va="center", fontsize=7, color=colour)
    ax.set_yticks(range(len(conditions)), [condition_label(c) for c in conditions])
    ax.set_xticks(range(len(columns)), [f"{a}\n{s}" for a, s in columns], fontsize=8)
    fig.colorbar(image, ax=ax, label="TSR change after - before (pp)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ----------------------------------------------------------------------------------------------------------------
# entry points
# ----------------------------------------------------------------------------------------------------------------
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
    before, after = list(before or []), list(after or [])
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

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written: dict[str, Path] = {}

    def write(name: str, text: str) -> None:
        (out / name).write_text(text)
        written[name] = out / name

    results: list[dict[str, Any]] = []
    if runs:
        table = robustness_table(runs)
        write("robustness.md", table.markdown())
        write("robustness.csv", table.csv())
        write("robustness.tex", table.latex())
        results = results_rows(runs)
        write_records(out / "results.csv", results)
        written["results.csv"] = out / "results.csv"
        if figures:
            plot_tsr_vs_intensity(runs, out / "tsr_vs_intensity.png")
            written["tsr_vs_intensity.png"] = out / "tsr_vs_intensity.png"
    changes: list[dict[str, Any]] = []
    if pairs:
        table, changes = before_after(pairs)
        write("before_after.md", table.markdown())
        write("before_after.csv", table.csv())
        write("before_after.tex", table.latex())
        write_records(out / "before_after_tests.csv", changes)
        written["before_after_tests.csv"] = out / "before_after_tests.csv"
        if figures:
            plot_before_after(changes, out / "before_after_heatmap.png")
            written["before_after_heatmap.png"] = out / "before_after_heatmap.png"
    deviations: list[dict[str, Any]] = []
    if offline:
        table, deviations = offline_table(offline)
        write("offline.md", table.markdown())
        write("offline.csv", table.csv())
        write("offline.tex", table.latex())
        write_records(out / "offline_results.csv", deviations)
        written["offline_results.csv"] = out / "offline_results.csv"
    write("summary.md", summary_text(results, changes, deviations))
    return written


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
