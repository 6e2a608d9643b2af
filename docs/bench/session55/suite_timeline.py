"""Per-worker and per-group test time of a suite run: ``pytest -v -n 2 --dist loadgroup --durations=0 > LOG``.

    python suite_timeline.py LOG

A test's time is its setup + call + teardown durations; a worker's, the sum over the tests its ``[gwN]`` lines
report; a group's, the sum over the tests of its xdist group (the id's ``@`` suffix, as tests/conftest.py marks it).
"""

import re
import sys
from collections import defaultdict
from pathlib import Path

DONE = re.compile(r"^\[(gw\d+)\] \[\s*\d+%\] [A-Z]+ (.+?)\s*$")
DURATION = re.compile(r"^([\d.]+)s (?:setup|call|teardown)\s+(.+?)\s*$")


def main() -> None:
    lines = Path(sys.argv[1]).read_text().splitlines()
    seconds: dict[str, float] = defaultdict(float)
    for line in lines:
        match = DURATION.match(line)
        if match:
            seconds[match.group(2)] += float(match.group(1))
    workers: dict[str, float] = defaultdict(float)
    groups: dict[str, float] = defaultdict(float)
    group_worker: dict[str, str] = {}
    counted = set()
    for line in lines:
        match = DONE.match(line)
        if not match or match.group(2) in counted:
            continue
        worker, test = match.groups()
        counted.add(test)
        group = test.rsplit("@", 1)[-1]
        workers[worker] += seconds.get(test, 0.0)
        groups[group] += seconds.get(test, 0.0)
        group_worker.setdefault(group, worker)
    print(f"test time: {sum(seconds.values()):.0f} s over {len(seconds)} tests with a duration line")
    for worker, total in sorted(workers.items()):
        print(f"{worker}: {total:.0f} s")
    calibration = sum(total for group, total in groups.items() if group.startswith("calibration/"))
    share = calibration / max(sum(groups.values()), 1e-9)
    print(f"calibration/ test files: {calibration:.0f} s, {100 * share:.0f}% of the test time")
    print("groups over 10 s, largest first (seconds, worker, group):")
    for group, total in sorted(groups.items(), key=lambda item: -item[1]):
        if total > 10:
            print(f"{total:8.0f}  {group_worker[group]}  {group}")


if __name__ == "__main__":
    main()
