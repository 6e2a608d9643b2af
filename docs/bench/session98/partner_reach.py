"""How far session 97's lead would reach: per calibrated case (``CASE/out/report.json`` under the given folders),
the effects a selection pass took and identification withdrew for a parameter at a bound of its range alone
(rule 3), and, for each, the candidates that would partner it: the pass's selected model with the partner added,
scored as selection scores it (the pass's inner folds), with the members a fold fit pins at a bound, and refitted on
all fit items, the withdrawn effect's and the partner's own parameters at a bound. The rule would fire where such a
model pins neither and scores the margin under the written model's score. Reads the pairs where the report says;
changes nothing. Usage: ``PYTHONPATH=. python docs/bench/session98/partner_reach.py ROOT...``."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

from lerobot_phantom.calibration import core
from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem

BOUND_REASON = re.compile(r"sits at its (low|high) bound")


def bound_only(withdrawal: dict) -> bool:
    return bool(withdrawal["reasons"]) and all(BOUND_REASON.search(r) for r in withdrawal["reasons"])


def own_at_bound(problem, model: frozenset[str], effect: str, fit) -> list[str]:
    limits = core.physical_limits(core.own_params(problem, model, effect))
    found = []
    for spec in core.own_params(problem, model, effect):
        side = core.at_bound(fit.params[spec.name], spec.low, spec.high)
        if side is not None and not limits.get(spec.name, {}).get(side):
            found.append(f"{spec.name}={fit.params[spec.name]:.4g} ({side})")
    return found


def partners(report: dict, withdrawal: dict) -> None:
    selection = report["selection"]
    taken_in = next(p for p in selection["earlier_passes"] if p["pass"] == withdrawal["pass"])
    model = frozenset(taken_in["selected"])
    effect = withdrawal["effect"]
    cfg = CalibrateConfig(
        attack=report["attack"], measured=report["input"]["path"], seed=report["split"]["seed"]
    )
    problem = build_problem(cfg)
    fit_items, _ = core.seeded_split(problem.n_items, cfg.heldout, cfg.seed)
    splits = core.selection_folds(fit_items, cfg.folds, cfg.seed, 2500)  # as forward_select
    written = selection["steps"][-1]["validation_error"]
    requires = core.requirements(problem)
    offered = [
        c.name for c in problem.candidates if c.name not in model and c.name not in selection["not_offered"]
    ]
    print(
        f"  withdrew {effect} (pass {withdrawal['pass']}: {', '.join(sorted(model))}); written score {written:.3f}"
    )
    for partner in offered:
        with_partner = model | {partner}
        if not requires[partner] <= with_partner or core.exclusive(problem.candidates, with_partner):
            continue
        score, fold_fits, _ = core.cross_validated(problem, with_partner, splits, None)
        pinned = core.pinned_members(problem, with_partner, with_partner, fold_fits)
        fit = problem.fit(with_partner, fit_items)
        refit = own_at_bound(problem, with_partner, effect, fit) + own_at_bound(
            problem, with_partner, partner, fit
        )
        fires = not pinned and not refit and score <= (1.0 - cfg.margin) * written
        print(
            f"    + {partner}: cross-validated {score:.3f} ({score / written:.3f} of written); folds pin "
            f"{pinned or 'none'}; refit at a bound {refit or 'none'}{'; FIRES' if fires else ''}",
            flush=True,
        )


def main() -> None:
    for root in sys.argv[1:]:
        for path in sorted(Path(root).rglob("out/report.json")):
            report = json.loads(path.read_text())
            found = [w for w in report["selection"].get("withdrawn", []) if bound_only(w)]
            print(
                f"{path.parent.parent.relative_to(root)}: {len(found)} withdrawn at a bound alone", flush=True
            )
            for withdrawal in found:
                partners(report, withdrawal)


if __name__ == "__main__":
    main()
