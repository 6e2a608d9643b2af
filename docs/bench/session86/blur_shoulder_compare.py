"""The blur cases of two camsim runs on the same master seeds, side by side: the package before the blur offered the
tone curve's shoulder (OLD) and after (NEW). Per case and seed: the camera's tone curve, the causes named, the
verdict by the test's rule, and the written model's held-out error; then each case's verdicts and, by tone curve, the
held-out error's ratio NEW / OLD (median and range).

Usage: ``CAMSIM_CASES=all PYTHONPATH=. python docs/bench/session86/blur_shoulder_compare.py OLD NEW`` (each a
``run_camsim_case.py`` OUTDIR).
"""

from __future__ import annotations

import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1]))

from camsim_named_causes import case_results


def results(out: str) -> dict[tuple[str, str], tuple[dict, dict]]:
    return {
        (seed, case.name): (report, judged) for seed, _sim, case, report, judged in case_results(Path(out))
    }


def main() -> None:
    old, new = results(sys.argv[1]), results(sys.argv[2])
    verdicts: dict[str, list[tuple[bool, bool]]] = defaultdict(list)
    ratios: dict[tuple[str, str], list[float]] = defaultdict(list)
    for key in sorted(old.keys() & new.keys(), key=lambda k: (k[1], k[0])):
        seed, name = key
        (old_report, old_judged), (new_report, new_judged) = old[key], new[key]
        tone = new_judged["camera"].tone
        before = old_report["extended"]["heldout_rmse"]
        after = new_report["extended"]["heldout_rmse"]
        verdicts[name].append((old_judged["passed"], new_judged["passed"]))
        ratios[(name, tone)].append(after / before)
        print(
            f"{name:22s} {seed:>10} {tone:6s} named {sorted(old_judged['named'])} -> {sorted(new_judged['named'])}; "
            f"{'OK' if old_judged['passed'] else 'MISS'} -> {'OK' if new_judged['passed'] else 'MISS'}; "
            f"held-out {before:.2f} -> {after:.2f}"
        )
    print(f"missing from one run: {sorted(old.keys() ^ new.keys())}")
    for name, pairs in sorted(verdicts.items()):
        print(f"{name}: passed {sum(o for o, _ in pairs)} -> {sum(n for _, n in pairs)} of {len(pairs)}")
    for (name, tone), values in sorted(ratios.items()):
        print(
            f"{name} on {tone} cameras ({len(values)}): held-out NEW / OLD median {np.median(values):.3f}, "
            f"range {min(values):.3f}-{max(values):.3f}"
        )


if __name__ == "__main__":
    main()
