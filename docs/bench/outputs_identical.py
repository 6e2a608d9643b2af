"""Are two trees of calibration outputs byte-identical? For a change that must not change any result (a refactor).

Usage: ``python docs/bench/outputs_identical.py BEFORE_DIR AFTER_DIR [--same OLD=NEW ...]``

Every ``report.json``, ``report.md`` and ``calibrated.json`` under BEFORE_DIR is compared with the file at the same
relative path under AFTER_DIR. ``--same OLD=NEW`` declares two strings equal (the checkout or the scratch folder a
report names as its input path); each is replaced by a placeholder on its side before comparing. Prints one line per
file that differs or is missing, the first differing lines, and a count. Exit status 1 if any differ.
"""

from __future__ import annotations

import argparse
import difflib
import sys
from pathlib import Path

COMPARED = ("report.json", "report.md", "calibrated.json")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument(
        "--same", action="append", default=[], help="OLD=NEW: strings that name the same thing"
    )
    args = parser.parse_args()
    pairs = []
    for same in args.same:
        old, sep, new = same.partition("=")
        if not sep or not old or not new:
            raise SystemExit(f"--same takes OLD=NEW, got {same!r}")
        pairs.append((old, new))
    compared = differ = 0
    for before in sorted(p for p in args.before.rglob("*") if p.name in COMPARED):
        after = args.after / before.relative_to(args.before)
        compared += 1
        if not after.exists():
            print(f"missing: {after}")
            differ += 1
            continue
        old_text, new_text = before.read_text(), after.read_text()
        for k, (old, new) in enumerate(pairs):
            old_text, new_text = old_text.replace(old, f"<same{k}>"), new_text.replace(new, f"<same{k}>")
        if old_text != new_text:
            differ += 1
            print(f"differs: {before.relative_to(args.before)}")
            diff = difflib.unified_diff(old_text.splitlines(), new_text.splitlines(), lineterm="", n=0)
            for line in list(diff)[2:8]:
                print(f"    {line[:160]}")
    print(f"{compared} files compared, {differ} differ")
    sys.exit(1 if differ or not compared else 0)


if __name__ == "__main__":
    main()
