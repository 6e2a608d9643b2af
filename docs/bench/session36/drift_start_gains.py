"""drift_from_entry's gain on the test simulator's drifting tables, the placement start against the entry start.

``test_the_entry_start_is_told_from_any_whole_placement``'s draws for each ``STRIPES_SEED`` (one camera and one set
of drifts, two of five recordings drifting a third to two thirds of a period; bootstrap 10; held-out split seed
``SEED % 1000`` as the test module uses). Prints one line per seed: for each start, whether drift_from_entry and
phase_drift are named, and the interval of the cross-validated error ratio drift_from_entry was identified on.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session36/drift_start_gains.py SEED [SEED ...]``
"""

import os
import sys
import tempfile
from pathlib import Path


def main(seeds: list[int]) -> None:
    os.environ.setdefault("STRIPES_SEED", str(seeds[0]))  # the test module reads one at import
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    for seed in seeds:
        test_stripes.SEED = seed  # calibrate_stripes' held-out split seed is SEED % 1000
        line = [str(seed)]
        for start_at in ("placement", "entry"):
            rng, camera, drifts = test_stripes.drifting_draw(seed, drifting=True)
            scratch = Path(tempfile.mkdtemp())
            test_stripes.drifting_table(scratch / "d.csv", camera, rng, drifts, start_at=start_at)
            report = test_stripes.calibrate_stripes(
                scratch, scratch / "d.csv", camera["height"], bootstrap=10
            )
            named = {f["effect"] for f in report["findings"]}
            gain = test_stripes.gain_interval(report, "drift_from_entry")
            ratio = next(
                (
                    r["validation_ratio"]["estimate"]
                    for r in report["identification"]
                    if r["effect"] == "drift_from_entry"
                ),
                None,
            )
            line.append(
                f"{start_at}: drift_from_entry named {'drift_from_entry' in named}, phase_drift named "
                f"{'phase_drift' in named}, gain {ratio if ratio is None else round(ratio, 3)} "
                f"interval {gain if gain is None else tuple(round(v, 3) for v in gain)}"
            )
        print(" | ".join(line), flush=True)


if __name__ == "__main__":
    main([int(s) for s in sys.argv[1:]])
