"""Two runs of ``camsim_case_batch.py`` on the same master seeds compared: cases with every planted effect named,
unplanted causes, and the written model's held-out RMSE (median, and on how many seeds the second run's is lower).

Usage: ``python docs/bench/camsim_batch_compare.py BEFORE.txt [BEFORE2.txt ...] -- AFTER.txt [AFTER2.txt ...]``
(the files of each side are joined; a seed is compared when both sides have it).
"""

from __future__ import annotations

import ast
import re
import statistics
import sys

LINE = re.compile(
    r"^(?P<case>\S+) (?P<seed>\d+) planted-missing (?P<missing>\[.*?\]) named (?P<named>\[.*?\]) "
    r"tone (?P<tone>\S+) heldout (?P<base>[\d.]+) -> (?P<written>[\d.]+)"
)


def load(paths: list[str]) -> dict[str, dict]:
    rows = {}
    for path in paths:
        with open(path) as lines:
            text = lines.read().splitlines()
        for line in text:
            match = LINE.match(line)
            if match is None:
                raise ValueError(f"{path}: not a camsim_case_batch line: {line!r}")
            row = match.groupdict()
            row["missing"] = ast.literal_eval(row["missing"])
            row["named"] = ast.literal_eval(row["named"])
            rows[row["seed"]] = row
    return rows


def summary(rows: dict[str, dict], seeds: list[str]) -> str:
    named = sum(not rows[s]["missing"] for s in seeds)
    written = [float(rows[s]["written"]) for s in seeds]
    return f"all planted named {named}/{len(seeds)}, held-out RMSE of the written model median {statistics.median(written):.2f}"


def main() -> None:
    split = sys.argv.index("--")
    before, after = load(sys.argv[1:split]), load(sys.argv[split + 1 :])
    seeds = [s for s in after if s in before]
    print(f"{len(seeds)} seeds in both")
    print("before:", summary(before, seeds))
    print("after: ", summary(after, seeds))
    lower = sum(float(after[s]["written"]) < float(before[s]["written"]) for s in seeds)
    print(f"held-out RMSE lower after on {lower} of {len(seeds)}")
    for s in seeds:
        b, a = before[s], after[s]
        print(
            f"  {s} {a['tone']:7s} before {b['written']:>6s} named {b['named']} | after {a['written']:>6s} named {a['named']}"
        )


if __name__ == "__main__":
    main()
