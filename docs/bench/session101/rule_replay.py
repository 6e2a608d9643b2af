"""Replays each selection step recorded in the report.json files under the given directories with the current
package's ``core.joint_group_taken`` and with an older ``core.py``'s, on the step's own recorded scores, and prints
every report where the two take different groups: the first such step of each pass (later steps of the pass were
never scored on the other path, so where a changed step leads is for a rerun to say).

A step's eligible groups are its ``tried`` minus its ``set_aside``; the groups with the simpler of two forms that
outscored a richer one are read from the set-aside reason, as ``core.groups_set_aside`` writes it. A step that took
no group is replayed as well: the older rule may have kept a group from it. Effects' ``requires`` are the package's.

usage: PYTHONPATH=. python docs/bench/session101/rule_replay.py OLD_CORE_PY DIR...
"""

import importlib.util
import json
import re
import sys
from pathlib import Path
from types import SimpleNamespace

from lerobot_phantom.calibration import core, projection, stripes
from lerobot_phantom.calibration.frame_models import (
    em_color_strip,
    em_truncation,
    laser_blinding,
    laser_color_strip,
    ultrasound_blur,
)

# per attack, the effect sets its problems offer (the laser strip: a stripe table's or frame pairs')
EFFECTS = {
    "light_projection": [projection.FRAME_EFFECTS],
    "laser_blinding": [laser_blinding.BLINDING_EFFECTS],
    "ultrasound_blur": [ultrasound_blur.BLUR_EFFECTS],
    "em_color_strip": [em_color_strip.EM_EFFECTS],
    "em_truncation": [em_truncation.TRUNCATION_EFFECTS],
    "laser_color_strip": [laser_color_strip.STRIP_EFFECTS, stripes.EFFECTS],
}
SIMPLER = re.compile(r"not \d+% under (\S+), the same model with the simpler form")

spec = importlib.util.spec_from_file_location("old_core", sys.argv[1])
old_core = importlib.util.module_from_spec(spec)
sys.modules["old_core"] = old_core  # its dataclasses look their module up
spec.loader.exec_module(old_core)
margin = 0.05


def taken(module, problem, step: dict):
    scored = {frozenset(label.split("+")): v for label, v in step["tried"].items()}
    aside = step.get("set_aside", {})
    set_aside = {frozenset(label.split("+")) for label in aside}
    eligible = {g: v for g, v in scored.items() if g not in set_aside}
    outscored = {}
    for label, why in aside.items():
        simpler = SIMPLER.fullmatch(why)
        if simpler:
            outscored[frozenset(label.split("+"))] = frozenset(simpler.group(1).split("+"))
    joint, _ = module.joint_group_taken(
        problem, eligible, step["validation_error"], margin, module.stand_ins(outscored, scored)
    )
    if joint is not None:
        return joint, eligible[joint]
    single, _ = module.lowest_scoring(problem, {g: v for g, v in eligible.items() if len(g) == 1})
    if single is None or eligible[single] > (1.0 - margin) * step["validation_error"]:
        return frozenset(), step["validation_error"]
    return single, eligible[single]


def recorded(steps: list[dict], k: int) -> frozenset[str]:
    """What the pass took at step ``k``: the effects of the next step that scored groups (the steps inside a group
    taken at once score none), or of the last step, beyond step ``k``'s."""
    j = next((j for j in range(k + 1, len(steps)) if steps[j]["tried"]), len(steps) - 1)
    return frozenset(steps[j]["effects"]) - frozenset(steps[k]["effects"])


n_reports = n_steps = n_reproduced = 0
for root in sys.argv[2:]:
    for path in sorted(Path(root).rglob("report.json")):
        report = json.loads(path.read_text())
        tried = {
            e for step in report["selection"]["steps"] for label in step["tried"] for e in label.split("+")
        }
        effects = next(t for t in EFFECTS[report["attack"]] if tried <= {e.name for e in t})
        problem = SimpleNamespace(
            candidates=effects,
            tie_preference=stripes.StripeProblem.tie_preference if effects is stripes.EFFECTS else (),
        )
        n_reports += 1
        selection = report["selection"]
        passes = [selection["steps"]] + [p.get("steps", []) for p in selection.get("earlier_passes", [])]
        for steps in passes:
            for k, step in enumerate(steps):
                if not step["tried"]:
                    continue
                n_steps += 1
                new, old = taken(core, problem, step), taken(old_core, problem, step)
                n_reproduced += old[0] == recorded(steps, k)
                if new[0] != old[0]:
                    name = lambda g: "+".join(sorted(g)) or "(nothing)"  # noqa: E731
                    print(
                        f"{path.parent.parent.name:28s} from [{'+'.join(step['effects'])}] "
                        f"({step['validation_error']:.4g}): new {name(new[0])} {new[1]:.4g}, "
                        f"old {name(old[0])} {old[1]:.4g}  {path.parent}"
                    )
                    break
print(
    f"{n_reports} reports, {n_steps} steps replayed; the older rule takes what the report recorded in "
    f"{n_reproduced} of them"
)
