"""A suite run's test time in three parts: the ``sampled`` tests it drew, the camsim cases it drew, and the tests every
run runs (tests/sampling.py).

    python docs/bench/session60/suite_parts.py LOG   (from the repository root)

``LOG``: ``pytest -q -n auto --dist loadgroup --durations=0`` output. The sampled tests are collected from the checkout
(``-m sampled`` with ``SAMPLED_SHARE=all``); a test's time is its setup + call + teardown.
"""

import os
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

DURATION = re.compile(r"^([\d.]+)s (?:setup|call|teardown)\s+(.+?)@(\S+)$")


def sampled_ids() -> set[str]:
    listed = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "--collect-only",
            "-q",
            "-m",
            "sampled",
            "-p",
            "no:cacheprovider",
            "tests",
        ],
        capture_output=True,
        text=True,
        env={**os.environ, "SAMPLED_SHARE": "all", "HF_HUB_OFFLINE": "1"},
        check=True,
    )
    return {line for line in listed.stdout.splitlines() if "::" in line}


def main() -> None:
    sampled = sampled_ids()
    parts: Counter = Counter()
    for line in Path(sys.argv[1]).read_text().splitlines():
        match = DURATION.match(line.strip())
        if not match:
            continue
        node = match.group(2).strip()
        if node in sampled:
            parts["sampled tests drawn"] += float(match.group(1))
        elif "test_independent_sim.py::test_case[" in node:
            parts["camsim cases drawn"] += float(match.group(1))
        else:
            parts["every run"] += float(match.group(1))
    print(f"test time {sum(parts.values()):.0f} s ({len(sampled)} sampled tests in the checkout)")
    for name, seconds in parts.most_common():
        print(f"  {seconds:6.0f} s  {name}")
    drawn = parts["sampled tests drawn"] + parts["camsim cases drawn"]
    print(f"  {drawn:6.0f} s  drawn, both kinds ({100 * drawn / sum(parts.values()):.0f}% of the test time)")


if __name__ == "__main__":
    main()
