"""Session 61's EM truncation draws, the package before the count law's change against after it, paired by master
seed: ``python docs/bench/session61/compare_count_law.py BEFORE.txt AFTER.txt [BEFORE.txt AFTER.txt ...]``
(outputs of ``count_spread_cases.py``). Prints, per pair, the passes with their 90% exact binomial intervals, the
held-out predictive RMSE (median, and how many draws are better or worse by more than 0.01 grey levels) and the
lines whose named causes or fitted law differ; with several pairs, the same counts pooled, and for every pairing
the exact sign test on the seeds whose verdict changed."""

from __future__ import annotations

import re
import statistics
import sys

from scipy.stats import binomtest

LINE = re.compile(
    r"^(?P<case>\S+) (?P<seed>\d+) \(case seed \d+\) (?P<verdict>pass|FAIL) named (?P<named>\[.*?\]) "
    r"slope (?P<slope>[\d.]+) jitter (?P<jitter>[\d.]+) rows \| heldout (?P<heldout>[\d.]+) "
    r"\[(?P<low>[\d.]+), (?P<high>[\d.]+)\] registered (?P<registered>[\d.]+)"
)


def read(path: str) -> dict[str, dict]:
    rows = {}
    with open(path) as handle:
        for line in handle:
            match = LINE.match(line)
            if match:
                rows[match["seed"]] = match.groupdict()
    return rows


def passes_with_interval(passed: int, total: int) -> str:
    interval = binomtest(passed, total).proportion_ci(0.9, method="exact")
    return f"{passed} of {total} (90% interval {100 * interval.low:.1f}-{100 * interval.high:.1f}%)"


def changes(before: dict, after: dict, seeds: list[str]) -> tuple[int, int, int, int]:
    """(FAIL -> pass, pass -> FAIL, held-out better, held-out worse by more than 0.01)."""
    fixed = sum(before[s]["verdict"] == "FAIL" and after[s]["verdict"] == "pass" for s in seeds)
    broken = sum(before[s]["verdict"] == "pass" and after[s]["verdict"] == "FAIL" for s in seeds)
    better = sum(float(before[s]["heldout"]) - float(after[s]["heldout"]) > 0.01 for s in seeds)
    worse = sum(float(after[s]["heldout"]) - float(before[s]["heldout"]) > 0.01 for s in seeds)
    return fixed, broken, better, worse


def sign_test(fixed: int, broken: int) -> str:
    if fixed + broken == 0:
        return "no verdict changed"
    return f"{fixed} FAIL -> pass, {broken} back (exact sign test p = {binomtest(fixed, fixed + broken).pvalue:.3g})"


def compare(before: dict, after: dict) -> list[str]:
    seeds = [seed for seed in before if seed in after]
    case = before[seeds[0]]["case"]
    passes = [sum(rows[s]["verdict"] == "pass" for s in seeds) for rows in (before, after)]
    fixed, broken, better, worse = changes(before, after, seeds)
    print(
        f"{case}: {len(seeds)} master seeds; passes {passes_with_interval(passes[0], len(seeds))} before, "
        f"{passes_with_interval(passes[1], len(seeds))} after; {sign_test(fixed, broken)}"
    )
    held = [[float(rows[s]["heldout"]) for s in seeds] for rows in (before, after)]
    print(
        f"held-out predictive RMSE (grey levels): median {statistics.median(held[0]):.3f} -> "
        f"{statistics.median(held[1]):.3f}; mean {statistics.mean(held[0]):.3f} -> {statistics.mean(held[1]):.3f}; "
        f"{better} better, {worse} worse, {len(seeds) - better - worse} within 0.01"
    )
    # each run's predictive error beyond its own best registration (the frame's latent searched on itself)
    excess = [
        [float(rows[s]["heldout"]) - float(rows[s]["registered"]) for s in seeds] for rows in (before, after)
    ]
    print(
        f"predictive minus the best registration's RMSE: median {statistics.median(excess[0]):.3f} -> "
        f"{statistics.median(excess[1]):.3f}, largest {max(excess[0]):.3f} -> {max(excess[1]):.3f}"
    )
    for s in seeds:
        b, a = before[s], after[s]
        if any(b[key] != a[key] for key in ("named", "slope", "jitter", "heldout")):
            print(
                f"  {s}: {b['verdict']} {b['named']} slope {b['slope']} jitter {b['jitter']} heldout {b['heldout']} "
                f"-> {a['verdict']} {a['named']} slope {a['slope']} jitter {a['jitter']} heldout {a['heldout']}"
            )
    return seeds


def main() -> None:
    paths = sys.argv[1:]
    if len(paths) % 2:
        raise SystemExit("give BEFORE AFTER pairs of count_spread_cases.py outputs")
    pooled_before, pooled_after = {}, {}
    for first, second in zip(paths[::2], paths[1::2], strict=True):
        before, after = read(first), read(second)
        for seed in compare(before, after):
            pooled_before[f"{first}:{seed}"], pooled_after[f"{first}:{seed}"] = before[seed], after[seed]
        print()
    if len(paths) > 2:
        seeds = list(pooled_before)
        passes = [sum(rows[s]["verdict"] == "pass" for s in seeds) for rows in (pooled_before, pooled_after)]
        fixed, broken, better, worse = changes(pooled_before, pooled_after, seeds)
        print(
            f"pooled, {len(seeds)} master seeds: passes {passes_with_interval(passes[0], len(seeds))} before, "
            f"{passes_with_interval(passes[1], len(seeds))} after; {sign_test(fixed, broken)}; held-out "
            f"{better} better, {worse} worse"
        )


if __name__ == "__main__":
    main()
