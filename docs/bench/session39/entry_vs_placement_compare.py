"""Side by side: two runs of ``session38/entry_vs_placement_gains.py`` on the same seeds (before and after a change),
per seed and start: the held-out RMSE and drift_from_entry's gain interval (or "not named"), then the entry and
placement tables' held-out RMSE counts and medians, and whether each seed passes the entry-vs-placement test's
claim (on the placement table drift_from_entry is not named, or its interval lies wholly below the entry table's).

    python docs/bench/session39/entry_vs_placement_compare.py BEFORE.txt AFTER.txt
"""

import re
import sys

import numpy as np


def parse(path: str) -> dict[tuple[str, str], dict]:
    runs: dict[tuple[str, str], dict] = {}
    current = None
    with open(path) as lines:
        for line in lines:
            head = re.match(r"STRIPES_SEED=(\d+) (\w+): truth drifts", line)
            if head:
                current = (head.group(1), head.group(2))
                runs[current] = {"gain": None}
                continue
            gain = re.search(r"drift_from_entry: identified True, gain [\d.]+ \[([\d.]+), ([\d.]+)\]", line)
            if gain and current:
                runs[current]["gain"] = (float(gain.group(1)), float(gain.group(2)))
            held = re.search(r"held-out ([\d.]+) rows", line)
            if held and current:
                runs[current]["held"] = float(held.group(1))
    return runs


def claim_holds(runs: dict, seed: str) -> bool:
    placement, entry = runs[(seed, "placement")]["gain"], runs[(seed, "entry")]["gain"]
    return entry is not None and (placement is None or placement[1] < entry[0])


def main(before_path: str, after_path: str) -> None:
    before, after = parse(before_path), parse(after_path)
    seeds = [seed for seed, start in before if start == "entry" and (seed, "entry") in after]
    for seed in seeds:
        for start in ("placement", "entry"):
            cells = []
            for runs in (before, after):
                gain = runs[(seed, start)]["gain"]
                named = f"[{gain[0]:.2f}, {gain[1]:.2f}]" if gain else "not named"
                cells.append(f"held-out {runs[(seed, start)]['held']:6.2f}, drift_from_entry {named:>14}")
            print(f"{seed:>10} {start:9}: before {cells[0]} | after {cells[1]}")
        print(f"{'':>10} claim: before {claim_holds(before, seed)}, after {claim_holds(after, seed)}")
    for start in ("placement", "entry"):
        pairs = np.array([(before[(s, start)]["held"], after[(s, start)]["held"]) for s in seeds])
        named = [sum(runs[(s, start)]["gain"] is not None for s in seeds) for runs in (before, after)]
        print(
            f"{start}: held-out lower after on {int((pairs[:, 1] < pairs[:, 0]).sum())} of {len(seeds)}, higher on "
            f"{int((pairs[:, 1] > pairs[:, 0]).sum())}; median {np.median(pairs[:, 0]):.2f} -> "
            f"{np.median(pairs[:, 1]):.2f} rows; drift_from_entry named {named[0]} -> {named[1]} of {len(seeds)}"
        )
    held = [sum(claim_holds(runs, s) for s in seeds) for runs in (before, after)]
    print(f"the entry-vs-placement claim holds on {held[0]} -> {held[1]} of {len(seeds)} seeds")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
