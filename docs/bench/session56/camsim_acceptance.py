"""Issue 12's acceptance rules over ``camsim_core_batch.sh`` runs, pooled over their master seeds: planted effects
named in >= 90% of effect cases, at most one unplanted named cause in any case, null cases keep the base model, and
(the independent simulator's own rule) the cases with an effect the library lacks name nothing and report the
structure left. Judged by ``camsim_named_causes.case_results`` (the test's rules, cases whose report.json is
missing skipped); the named share carries a Clopper-Pearson 90% interval over the pooled cases and the p-value of
``test_planted_effects_are_named``'s rule (session 102).

Usage: ``CAMSIM_CASES=all PYTHONPATH=. python docs/bench/session56/camsim_acceptance.py OUTDIR...`` from the
repository root (the same ``CAMSIM_CASES`` as the batch).
"""

from __future__ import annotations

import importlib
import sys
from collections import defaultdict
from pathlib import Path

from scipy.stats import binomtest

sys.path.insert(0, str(Path(__file__).parents[1]))

from camsim_named_causes import case_results


def main() -> None:
    by_kind: dict[str, list[tuple[str, str, dict]]] = defaultdict(list)
    seeds = set()
    for out in sys.argv[1:]:
        for seed, _sim, case, _report, judged in case_results(Path(out)):
            seeds.add(seed)
            by_kind[case.kind].append((seed, case.name, judged))
    print(f"master seeds ({len(seeds)}): {' '.join(sorted(seeds))}")
    effect = by_kind["effect"]
    named = sum(judged["passed"] for _, _, judged in effect)
    interval = binomtest(named, len(effect)).proportion_ci(confidence_level=0.9, method="exact")
    print(
        f"effect cases with every planted effect named: {named} of {len(effect)} "
        f"({named / len(effect):.1%}, 90% interval {interval.low:.1%}-{interval.high:.1%})"
    )
    sim = importlib.import_module("test_independent_sim")  # as case_results last loaded it
    p_value = sim.named_share_p_value(named, len(effect))
    print(
        f"  so few named at a rate of {sim.NAMED_SHARE:.0%}: p = {p_value:.4f} "
        f"(test_planted_effects_are_named fails at p <= {sim.NAMED_SHARE_ALPHA})"
    )
    for seed, name, judged in effect:
        if not judged["passed"]:
            print(f"  missed: {name} (seed {seed}), named {sorted(judged['named'])}")
    inventing = [
        (seed, name, judged["unplanted"])
        for kind in ("effect", "null", "unexplained")
        for seed, name, judged in by_kind[kind]
        if len(judged["unplanted"]) > 1
    ]
    print(f"cases naming more than one unplanted cause: {len(inventing)} {inventing}")
    nulls = by_kind["null"]
    print(f"null cases keeping the base model: {sum(j['passed'] for _, _, j in nulls)} of {len(nulls)}")
    for seed, name, judged in nulls:
        if not judged["passed"]:
            print(f"  gained: {name} (seed {seed}), named {sorted(judged['named'])}")
    unexplained = by_kind["unexplained"]
    print(
        "cases with an effect the library lacks, nothing named and the structure reported: "
        f"{sum(j['passed'] for _, _, j in unexplained)} of {len(unexplained)}"
    )
    for seed, name, judged in unexplained:
        if not judged["passed"]:
            print(f"  not passed: {name} (seed {seed}), named {sorted(judged['named'])}")


if __name__ == "__main__":
    main()
