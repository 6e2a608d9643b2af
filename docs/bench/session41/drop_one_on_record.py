"""For the camsim cases where session 41's group rule moved an effect's compared steps: the score of the model
without that effect (the compared model minus the effect), where selection happened to score it (a step or a tried
group), against the compared model's. A drop-one reading of the same evidence, from what report.json holds; no refit.

    python docs/bench/session41/drop_one_on_record.py BEFORE_DIR AFTER_DIR SEED [SEED ...]
"""

import json
import sys
from pathlib import Path


def scored_models(steps: list[dict]) -> dict[frozenset, float]:
    """Every model selection scored: each step's, and each tried group on top of its step."""
    scores = {}
    for step in steps:
        base = frozenset(step["effects"])
        scores[base] = step["validation_error"]
        for label, score in step["tried"].items():
            scores.setdefault(base | set(label.split("+")), score)
    return scores


before_dir, after_dir, seeds = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3:]
for seed in seeds:
    for after_report in sorted((after_dir / f"bt_{seed}").glob("*/*/out/report.json")):
        if (
            after_report.parent.parent.parent.is_symlink()
        ):  # pytest's "<name>current" link to the numbered basetemp
            continue
        case = after_report.parent.parent.name
        after = json.loads(after_report.read_text())
        before = json.loads((before_dir / after_report.relative_to(after_dir)).read_text())
        old = {r["effect"]: r.get("compared_steps") for r in before["identification"]}
        steps = after["selection"]["steps"]
        scores = scored_models(steps)
        for result in after["identification"]:
            effect, compared = result["effect"], result.get("compared_steps")
            if compared is None or compared == old.get(effect):
                continue
            with_it = frozenset(steps[compared[1]]["effects"])
            if (
                effect not in with_it
            ):  # a cause implied by a form in the model (Effect.implies) has no term to drop
                continue
            without = with_it - {effect}
            on_record = scores.get(without)
            print(
                f"seed {seed} {case} {effect}: compared {old.get(effect)} -> {compared}; with it "
                f"{sorted(with_it)} {steps[compared[1]]['validation_error']:.4g}, without it "
                + (f"{on_record:.4g}" if on_record is not None else "not scored by selection")
            )
