"""Test time per xdist group of a suite run: ``pytest -q -n auto --dist loadgroup --durations=0 > LOG``.

    python suite_groups.py LOG

A test's time is its setup + call + teardown; a group's (the id's ``@`` suffix, as tests/conftest.py marks it), the
sum over its tests. Prints the total, the groups over 10 s and the 25 longest tests.
"""

import re
import sys
from collections import Counter
from pathlib import Path

DURATION = re.compile(r"^([\d.]+)s (?:setup|call|teardown)\s+(\S+?)@(\S+)")


def main() -> None:
    groups: Counter = Counter()
    tests: Counter = Counter()
    for line in Path(sys.argv[1]).read_text().splitlines():
        match = DURATION.match(line)
        if match:
            seconds = float(match.group(1))
            tests[match.group(2)] += seconds
            groups[match.group(3)] += seconds
    total = sum(groups.values())
    calibration = sum(v for k, v in groups.items() if k.startswith("calibration/"))
    print(
        f"test time {total:.0f} s; calibration/ files {calibration:.0f} s ({100 * calibration / total:.0f}%)"
    )
    for name, seconds in groups.most_common():
        if seconds >= 10:
            print(f"{seconds:8.0f}  {name}")
    print("longest tests:")
    for name, seconds in tests.most_common(25):
        print(f"{seconds:8.0f}  {name}")


if __name__ == "__main__":
    main()
