"""Session 61's EM truncation draws, the package before the count law's change against after it, paired by master
seed: ``python docs/bench/session61/compare_count_law.py BEFORE.txt AFTER.txt`` (outputs of
``count_spread_cases.py``). Prints the passes, the held-out predictive RMSE (median, and how many draws are better
or worse by more than 0.01 grey levels), and the lines whose named causes or fitted law differ."""

from __future__ import annotations

import re
import statistics
import sys

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


def main() -> None:
    before, after = read(sys.argv[1]), read(sys.argv[2])
    seeds = [seed for seed in before if seed in after]
    case = before[seeds[0]]["case"]
    passes = [sum(rows[s]["verdict"] == "pass" for s in seeds) for rows in (before, after)]
    print(f"{case}: {len(seeds)} master seeds; passes {passes[0]} before, {passes[1]} after")
    held = [[float(rows[s]["heldout"]) for s in seeds] for rows in (before, after)]
    better = sum(b - a > 0.01 for b, a in zip(*held, strict=True))
    worse = sum(a - b > 0.01 for b, a in zip(*held, strict=True))
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
        if (b["named"], b["slope"], b["jitter"], b["heldout"]) != (
            a["named"],
            a["slope"],
            a["jitter"],
            a["heldout"],
        ):
            print(
                f"  {s}: {b['verdict']} {b['named']} slope {b['slope']} jitter {b['jitter']} heldout {b['heldout']} "
                f"-> {a['verdict']} {a['named']} slope {a['slope']} jitter {a['jitter']} heldout {a['heldout']}"
            )


if __name__ == "__main__":
    main()
