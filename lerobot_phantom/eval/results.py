"""The eval.json schema shared by ``lerobot-phantom-eval`` (writer) and ``lerobot-phantom-report`` (reader).

Kept free of torch/LeRobot imports so that reports render quickly anywhere.

``{"format": EVAL_FORMAT, "mode": "rollout" | "offline", "metadata": {...}, "results": [...], "summary": [...]}``;
a rollout result row is one condition on one task: ``condition`` (``"clean"``, ``"<attack>@<intensity>"`` or, for
all-or-nothing instruction attacks, ``"<attack>"``), ``attack``, ``intensity``, ``intensity_value``, ``suite``,
``task_id``, ``successes``, ``episodes``, ``tsr``, ``ci95`` and ``per_episode`` (``seed``, ``success``, rewards,
``steps``, ``attack_params``).
"""

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
