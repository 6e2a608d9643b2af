"""Count, per master seed of a ``camsim_core_batch.sh`` run, the effect cases whose planted effects were named.

Usage: ``PYTHONPATH=. python docs/bench/camsim_batch_misses.py OUTDIR`` from the repository root. Reads every case's
``report.json`` that the batch kept under ``OUTDIR/bt_SEED`` and applies the naming test's own rule
(``test_independent_sim.named_causes``) to the cases that master seed selected (``CAMSIM_CASES`` as in the batch),
so seeds whose >= 90% test passed are counted too; also the effect cases naming more than one unplanted cause and
the null cases that gained an effect (what the case tests assert).
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from camsim_named_causes import case_results


def main() -> None:
    results = case_results(Path(sys.argv[1]), skip_missing=False)
    for seed, cases in itertools.groupby(results, key=lambda result: result[0]):
        misses, inventing, gained, effect_cases = [], [], [], 0
        for _seed, _sim, case, report, judged in cases:
            if case.kind == "null":
                if report["extended"]["effects"]:
                    gained.append(f"{case.name} gained {sorted(report['extended']['effects'])}")
                continue
            if case.kind != "effect":
                continue
            effect_cases += 1
            if not judged["passed"]:
                misses.append(f"{case.name} named {sorted(judged['named'])}")
            if len(judged["unplanted"]) > 1:
                inventing.append(f"{case.name} unplanted {sorted(judged['unplanted'])}")
        print(
            f"seed {seed}: {effect_cases - len(misses)} of {effect_cases} effect cases named; misses: "
            f"{'; '.join(misses)}"
            + (f"; more than one unplanted cause: {'; '.join(inventing)}" if inventing else "")
            + (f"; null cases that gained an effect: {'; '.join(gained)}" if gained else "")
        )


if __name__ == "__main__":
    main()
