"""The eval.json schema shared by ``lerobot-phantom-eval`` (writer) and ``lerobot-phantom-report`` (reader).

Kept free of torch/LeRobot imports so that reports render quickly anywhere.

``{"format": EVAL_FORMAT, "mode": "rollout" | "offline", "metadata": {...}, "results": [...], "summary": [...]}``;
a rollout result row is one condition on one task: ``condition`` (``"clean"``, ``"<attack>@<intensity>"`` or, for
all-or-nothing instruction attacks, ``"<attack>"``), ``attack``, ``intensity``, ``intensity_value``, ``suite``,
``task_id`` (LeRobot's env id within the suite: 0 for a suite that draws its task per episode), ``successes``,
``episodes``, ``tsr``, ``ci95`` and ``per_episode`` (``seed``, ``task_index``, ``task``, ``instruction``,
``success``, rewards, ``steps``, ``attack_params``). ``summary`` pools every task per condition;
``summary_per_task`` has one row per (condition, suite, task).
"""

import json
from pathlib import Path
from typing import Any

from lerobot_phantom.eval.stats import wilson_interval

EVAL_FORMAT = "lerobot_phantom.eval/1"
EVAL_FILENAME = "eval.json"
CLEAN = "clean"


def summarize(records: list[dict[str, Any]]) -> dict[str, Any]:
    """Successes, episodes, TSR and its 95 % Wilson interval of per-episode records."""
    successes = sum(int(r["success"]) for r in records)
    episodes = len(records)
    low, high = wilson_interval(successes, episodes)
    return {"successes": successes, "episodes": episodes, "tsr": successes / episodes, "ci95": [low, high]}


def pooled_summary(results: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per condition, pooled over every task: the headline numbers."""
    keys = list(dict.fromkeys(r["condition"] for r in results))
    return [
        {
            "condition": key,
            **summarize([e for r in results if r["condition"] == key for e in r["per_episode"]]),
        }
        for key in keys
    ]


def episode_task(episode: dict[str, Any]) -> tuple[Any, str]:
    """(task index, readable task name) of a per-episode record; files written before tasks were recorded have
    neither (one unnamed task)."""
    name = episode.get("task") or episode.get("instruction") or "?"
    return episode.get("task_index"), name


def per_task_summary(results: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per condition, suite and task (as each episode recorded it), in first-seen order."""
    groups: dict[tuple, list[dict[str, Any]]] = {}
    instructions: dict[tuple, Any] = {}
    for row in results:
        for episode in row["per_episode"]:
            index, name = episode_task(episode)
            key = (row["condition"], row["suite"], index, name)
            groups.setdefault(key, []).append(episode)
            instructions.setdefault(key, episode.get("instruction"))
    return [
        {
            "condition": condition,
            "suite": suite,
            "task_index": index,
            "task": name,
            "instruction": instructions[(condition, suite, index, name)],
            **summarize(episodes),
        }
        for (condition, suite, index, name), episodes in groups.items()
    ]


def write_eval(output_dir: str | Path, report: dict[str, Any]) -> Path:
    """Write ``report`` to ``<output_dir>/eval.json`` (directory created); returns the file."""
    path = Path(output_dir) / EVAL_FILENAME
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        json.dump(report, f, indent=2)
    return path
