"""``lerobot-phantom-select-checkpoint``: pick one training checkpoint by its clean TSR on validation episodes.

On 2 CPU cores the clean TSR of SmolVLA checkpoints saved 250 steps apart jumps between 0% and 30% (docs/recipe:
the shipped recipe's step-2000 checkpoint scored 4% while step 1000 scored 30%), so "the last checkpoint" is a coin
toss. This tool reads one ``lerobot-phantom-eval`` result per candidate checkpoint (run on validation seeds that the
final evaluation never uses), selects the candidate with the most successes in ``--condition`` (ties: the latest,
i.e. the one listed last), copies its ``pretrained_model`` to ``<output_dir>/checkpoints/last/pretrained_model`` (the
layout ``--policy.path`` users and the study expect) and writes ``selection.json`` with every candidate's
successes and 95 % Wilson interval.

    lerobot-phantom-select-checkpoint \\
        --evals='["val/000250/eval.json","val/000500/eval.json"]' \\
        --checkpoints='["train/clean/checkpoints/000250/pretrained_model","train/clean/checkpoints/000500/pretrained_model"]' \\
        --output_dir=train/selected
"""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lerobot_phantom.eval.results import CLEAN
from lerobot_phantom.eval.stats import wilson_interval

SELECTION_FILE = "selection.json"
SELECTED_MODEL = "checkpoints/last/pretrained_model"
RULE = "most successes in the condition on the validation episodes; ties go to the latest checkpoint"


@dataclass
class SelectCheckpointConfig:
    # eval.json of each candidate, in training order (lerobot-phantom-eval on validation seeds).
    evals: list[str] = field(default_factory=list)
    # The pretrained_model directory each eval.json evaluated, same order.
    checkpoints: list[str] = field(default_factory=list)
    # Written: selection.json and checkpoints/last/pretrained_model (a copy of the selected one).
    output_dir: str = "outputs/selected"
    # The condition whose TSR decides.
    condition: str = CLEAN

    def __post_init__(self) -> None:
        if not self.evals:
            raise ValueError("--evals is empty: give one eval.json per candidate checkpoint")
        if len(self.evals) != len(self.checkpoints):
            raise ValueError(
                f"--evals lists {len(self.evals)} files but --checkpoints lists {len(self.checkpoints)}; "
                "give one eval.json per checkpoint, in the same order"
            )


def condition_counts(eval_path: Path, checkpoint: Path, condition: str) -> tuple[int, int]:
    """(successes, episodes) of ``condition`` in a finished rollout eval.json of ``checkpoint``."""
    report = json.loads(eval_path.read_text())
    metadata = report.get("metadata", {})
    if report.get("mode") != "rollout" or not metadata.get("complete"):
        raise ValueError(f"{eval_path} is not a finished rollout evaluation (lerobot-phantom-eval on an env)")
    evaluated = Path(metadata["policy"]["path"])
    if evaluated.resolve() != checkpoint.resolve():
        raise ValueError(
            f"{eval_path} evaluated {evaluated}, not {checkpoint}: --evals and --checkpoints must be in the same "
            "order"
        )
    rows = {row["condition"]: row for row in report["summary"]}
    if condition not in rows:
        raise ValueError(f"{eval_path} has no condition {condition!r}; it has {', '.join(rows)}")
    return int(rows[condition]["successes"]), int(rows[condition]["episodes"])


def select(cfg: SelectCheckpointConfig) -> dict[str, Any]:
    """Select, copy and record; returns the content of selection.json."""
    output = Path(cfg.output_dir)
    checkpoints = [Path(c) for c in cfg.checkpoints]
    for checkpoint in checkpoints:
        if not (checkpoint / "config.json").is_file():
            raise FileNotFoundError(f"{checkpoint} is not a policy checkpoint (no config.json)")
        if output.resolve() == checkpoint.resolve() or output.resolve() in checkpoint.resolve().parents:
            raise ValueError(
                f"--output_dir={output} contains the candidate {checkpoint}; choose another directory"
            )
    if (output / SELECTED_MODEL).exists():
        raise FileExistsError(
            f"{output / SELECTED_MODEL} exists; choose another --output_dir or remove it (nothing is overwritten)"
        )
    candidates = []
    for eval_path, checkpoint in zip(cfg.evals, checkpoints, strict=True):
        successes, episodes = condition_counts(Path(eval_path), checkpoint, cfg.condition)
        low, high = wilson_interval(successes, episodes)
        candidates.append(
            {
                "checkpoint": str(checkpoint),
                "eval": eval_path,
                "successes": successes,
                "episodes": episodes,
                "tsr": successes / episodes,
                "ci95": [low, high],
            }
        )
    # The index breaks ties in favour of the latest checkpoint.
    best = max(
        range(len(candidates)), key=lambda i: (candidates[i]["successes"] / candidates[i]["episodes"], i)
    )
    shutil.copytree(checkpoints[best], output / SELECTED_MODEL)
    selection = {
        "condition": cfg.condition,
        "rule": RULE,
        "selected": candidates[best]["checkpoint"],
        "selected_index": best,
        "policy_path": str(output / SELECTED_MODEL),
        "candidates": candidates,
    }
    (output / SELECTION_FILE).write_text(json.dumps(selection, indent=2))
    return selection


def main(args: list[str] | None = None) -> None:
    import sys

    import draccus

    from lerobot_phantom import register

    register()  # as every lerobot-phantom-* script does

    cfg = draccus.parse(SelectCheckpointConfig, args=sys.argv[1:] if args is None else args)
    selection = select(cfg)
    for i, c in enumerate(selection["candidates"]):
        low, high = c["ci95"]
        mark = "*" if i == selection["selected_index"] else " "
        print(
            f"{mark} {c['checkpoint']}: {cfg.condition} {100 * c['tsr']:.1f}% [{100 * low:.1f}, {100 * high:.1f}]"
            f" ({c['successes']}/{c['episodes']})"
        )
    print(f"selected {selection['selected']} -> {selection['policy_path']}")


if __name__ == "__main__":
    main()
