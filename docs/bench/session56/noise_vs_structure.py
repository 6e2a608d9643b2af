"""Over ``camsim_core_batch.sh`` runs: how often ``shot_noise`` is named (the noise model kept) where the report also
finds unexplained structure, by kind of case and whether photon noise was planted. Measures what a rule that holds
photon noise back wherever structure remains would change, from the reports alone.

Usage: ``CAMSIM_CASES=all PYTHONPATH=. python docs/bench/session56/noise_vs_structure.py OUTDIR...`` from the
repository root.
"""

import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1]))

from camsim_named_causes import case_results


def main() -> None:
    rows = []
    for out in sys.argv[1:]:
        for seed, _sim, case, report, _judged in case_results(Path(out)):
            rows.append(
                (
                    seed,
                    case.name,
                    case.kind,
                    "shot_noise" in case.planted,
                    bool(report.get("noise", {}).get("kept")),
                    bool(report["unexplained_structure"]["structure_remains"]),
                )
            )
    counts = Counter(row[2:] for row in rows)
    print("(kind, photon noise planted, shot_noise named, structure remains): cases")
    for key, count in sorted(counts.items()):
        print(key, count)
    for row in rows:
        if row[4] and row[5]:
            print("named where structure remains:", row[:3])


if __name__ == "__main__":
    main()
