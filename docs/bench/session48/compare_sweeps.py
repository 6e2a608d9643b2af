"""Two runs of ``docs/bench/second_camera_sweep.py`` side by side, case by case (seed x frame rule): the written
model's held-out RMSE, its fitted row time against the camera's, and the named effects; then the counts of cases
above the issue's 30-row bar, of row times within 5% of the camera's and of held-out errors at or under 10 rows, the
median held-out error, and how many cases got better or worse by more than 0.05 rows, over the cases both runs hold.

Usage: ``python docs/bench/session48/compare_sweeps.py BEFORE.txt [BEFORE.txt ...] -- AFTER.txt [AFTER.txt ...]``
"""

import re
import statistics
import sys

LINE = re.compile(
    r"^\s*(\d+) (\w+)\s+held-out\s+([\d.]+) rows \(base\s+([\d.]+)\) row time\s+([\d.na]+) us \(camera\s+([\d.]+)\)"
    r" named (\S*)"
)


def read(paths: list[str]) -> dict[tuple[str, str], tuple[float, float, float, str]]:
    cases = {}
    for path in paths:
        with open(path) as lines:
            for line in lines:
                match = LINE.match(line)
                if match:
                    seed, rule, heldout, _base, row_time, camera, named = match.groups()
                    cases[seed, rule] = (float(heldout), float(row_time), float(camera), named)
    return cases


def main(argv: list[str]) -> None:
    split = argv.index("--")
    before, after = read(argv[:split]), read(argv[split + 1 :])
    common = [case for case in before if case in after]
    counts = {"before": [0, 0], "after": [0, 0]}
    for case in common:
        cells = []
        for name, run in (("before", before), ("after", after)):
            heldout, row_time, camera, named = run[case]
            near = abs(row_time / camera - 1.0) <= 0.05
            counts[name][0] += heldout > 30.0
            counts[name][1] += near
            cells.append(f"{heldout:7.2f} rows, row time {row_time:6.1f} us{' ' if near else '*'} {named}")
        changed = "" if before[case][0] == after[case][0] else "  CHANGED"
        print(
            f"{case[0]:>10} {case[1]:8s} camera {before[case][2]:5.1f} us | {cells[0]} -> {cells[1]}{changed}"
        )
    for name, run in (("before", before), ("after", after)):
        above, near = counts[name]
        heldout = [run[case][0] for case in common]
        print(
            f"{name}: above 30 rows {above} of {len(common)}; row time within 5% of the camera's {near} of "
            f"{len(common)}; at or under 10 rows {sum(h <= 10.0 for h in heldout)} of {len(common)}; median held-out "
            f"{statistics.median(heldout):.2f} rows"
        )
    better = sum(after[case][0] < before[case][0] - 0.05 for case in common)
    worse = sum(after[case][0] > before[case][0] + 0.05 for case in common)
    print(f"better by more than 0.05 rows: {better}; worse: {worse}")
    print("(* marks a row time more than 5% from the camera's)")


if __name__ == "__main__":
    main(sys.argv[1:])
