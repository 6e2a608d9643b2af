"""Learning curves of the CPU recipe experiments: checkpoint TSRs (from recipe_rollouts.py) + training logs -> docs.

    python scripts/recipe_curve.py --rollouts A.json B.json ... --train-log A=DIR/A.log --train-log B=DIR/B.log
        [--start-step C=1500] [--load-log load.log] --out docs/recipe

Writes ``learning_curve.csv`` (one row per experiment, checkpoint and readout: TSR, 95 % Wilson interval, the
first-close grasp breakdown), ``training.json`` (per experiment: the training command, loss and seconds per step at
each logged step, wall time, machine load average while it ran) and ``learning_curve.png``. Experiment names are
the checkpoint's run directory (``<run>/checkpoints/<step>/pretrained_model``).
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import statistics
from datetime import datetime
from pathlib import Path

LOG_LINE = re.compile(
    r"INFO (\d{4}-\d\d-\d\d \d\d:\d\d:\d\d) .*? step:([\d.]+K?) .*?loss:([\d.]+) .*?updt_s:([\d.]+) "
    r"data_s:([\d.]+)"
)


def checkpoint_name(path: str) -> tuple[str, int]:
    parts = Path(path).parts
    index = parts.index("checkpoints")
    return parts[index - 1], int(parts[index + 1])


def curve_rows(rollout_files: list[Path], start_steps: dict[str, int]) -> list[dict]:
    rows = []
    for path in rollout_files:
        for summary in json.loads(path.read_text()):
            experiment, step = checkpoint_name(summary["checkpoint"])
            grasp = summary["grasp"]
            rows.append(
                {
                    "experiment": experiment,
                    "step": step,
                    # steps including those of the checkpoint a fine-tuning run started from
                    "total_step": start_steps.get(experiment, 0) + step,
                    "readout": f"replan{summary['replan']}"
                    + ("_zero_noise" if summary["zero_noise"] else ""),
                    "episodes": summary["episodes"],
                    "successes": summary["successes"],
                    "tsr": round(summary["tsr"], 4),
                    "wilson95_low": round(summary["wilson95"][0], 4),
                    "wilson95_high": round(summary["wilson95"][1], 4),
                    "first_close_grasped": grasp["first_close_grasped"],
                    "first_close_grasped_nothing": grasp["first_close_grasped_nothing"],
                    "no_close": grasp["no_close_at_all"],
                    "median_dxy_cm_miss": _cm(grasp["median_dxy_m_miss"]),
                    "median_dz_cm_miss": _cm(grasp["median_dz_m_miss"]),
                    "median_dxy_cm_hit": _cm(grasp["median_dxy_m_hit"]),
                    "median_dz_cm_hit": _cm(grasp["median_dz_m_hit"]),
                    "max_closes_in_an_episode": grasp["max_closes_in_an_episode"],
                    "median_action_err_vs_expert": summary["median_action_err_vs_expert"],
                    "per_task_successes": " ".join(
                        f"{task}:{v['successes']}/{v['episodes']}" for task, v in summary["per_task"].items()
                    ),
                    "eval_seconds": summary["seconds"],
                    "eval_load_average_1min": round(summary["load_average"][0], 2),
                    "rollouts_file": path.name,
                }
            )
    return sorted(rows, key=lambda r: (r["experiment"], r["readout"], r["step"]))


def _cm(metres: float | None) -> float | None:
    return None if metres is None else round(100 * metres, 2)


def training_record(log: Path, loads: list[tuple[datetime, float]]) -> dict:
    text = log.read_text(errors="replace")
    logged = []
    for m in LOG_LINE.finditer(text):
        # LeRobot prints steps from 1000 on rounded ("1K"): count on from the last exact step at the log interval.
        if m.group(2).endswith("K"):
            interval = logged[1]["step"] - logged[0]["step"]
            step = logged[-1]["step"] + interval
        else:
            step = int(m.group(2))
        logged.append(
            {
                "time": m.group(1),
                "step": step,
                "loss": float(m.group(3)),
                "update_s": float(m.group(4)),
                "data_s": float(m.group(5)),
            }
        )
    record: dict = {"log": log.name, "logged": logged}
    if logged:
        start = datetime.fromisoformat(logged[0]["time"])
        end = datetime.fromisoformat(logged[-1]["time"])
        during = [load for when, load in loads if start <= when <= end]
        steps = logged[-1]["step"] - logged[0]["step"]
        record.update(
            last_step=logged[-1]["step"],
            wall_minutes=round((end - start).total_seconds() / 60, 1),
            wall_s_per_step=round((end - start).total_seconds() / steps, 2) if steps else None,
            median_update_plus_data_s=round(
                statistics.median(r["update_s"] + r["data_s"] for r in logged), 2
            ),
            load_average_1min_median=round(statistics.median(during), 2) if during else None,
            load_average_1min_max=round(max(during), 2) if during else None,
        )
    return record


def read_loads(path: Path | None) -> list[tuple[datetime, float]]:
    if path is None:
        return []
    loads = []
    for line in path.read_text().splitlines():
        stamp, one_minute, *_ = line.split()
        loads.append((datetime.fromisoformat(stamp.replace("Z", "")), float(one_minute)))
    return loads


def plot(rows: list[dict], out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(7, 4))
    for key in dict.fromkeys((r["experiment"], r["readout"]) for r in rows):
        points = [r for r in rows if (r["experiment"], r["readout"]) == key]
        steps = [r["total_step"] for r in points]
        tsr = [100 * r["tsr"] for r in points]
        errors = [
            [100 * (r["tsr"] - r["wilson95_low"]) for r in points],
            [100 * (r["wilson95_high"] - r["tsr"]) for r in points],
        ]
        axis.errorbar(
            steps,
            tsr,
            yerr=errors,
            marker="o",
            linestyle="-" if len(steps) > 1 else "none",
            capsize=3,
            label=f"{key[0]} ({key[1]})",
        )
    axis.set_xlabel("training steps in total (batch 32; anneal runs: from their start checkpoint)")
    axis.set_ylabel("clean TSR on phantom_table goal (%)")
    axis.set_ylim(0, 100)
    axis.set_title(
        "SmolVLA on 2 CPU cores: clean task success per checkpoint\n(error bars: 95 % Wilson interval)"
    )
    axis.legend(fontsize=7)
    axis.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(out, dpi=120)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rollouts", nargs="+", type=Path, required=True)
    parser.add_argument("--train-log", action="append", default=[], help="NAME=PATH of a training log")
    parser.add_argument("--load-log", type=Path)
    parser.add_argument(
        "--start-step",
        action="append",
        default=[],
        help="NAME=STEPS: run NAME fine-tuned a STEPS-step checkpoint",
    )
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    start_steps = {name: int(steps) for name, _, steps in (s.partition("=") for s in args.start_step)}
    rows = curve_rows(args.rollouts, start_steps)
    with open(args.out / "learning_curve.csv", "w", newline="") as sink:
        writer = csv.DictWriter(sink, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    loads = read_loads(args.load_log)
    training = {}
    for item in args.train_log:
        name, _, path = item.partition("=")
        training[name] = training_record(Path(path), loads)
    (args.out / "training.json").write_text(json.dumps(training, indent=1) + "\n")
    plot(rows, args.out / "learning_curve.png")
    for row in rows:
        print(
            f"{row['experiment']:<14} step {row['step']:>5} {row['readout']:<18} TSR {row['successes']}/"
            f"{row['episodes']} = {100 * row['tsr']:.0f}% [{100 * row['wilson95_low']:.0f}, "
            f"{100 * row['wilson95_high']:.0f}] first close: {row['first_close_grasped']} grasped, "
            f"{row['first_close_grasped_nothing']} nothing (miss median dxy {row['median_dxy_cm_miss']} cm, "
            f"dz {row['median_dz_cm_miss']} cm)"
        )


if __name__ == "__main__":
    main()
