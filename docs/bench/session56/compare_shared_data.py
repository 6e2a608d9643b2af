"""Compare two outputs of ``docs/bench/calibration_shared_data.py``: per run, the largest relative change of any
fitted number (CPU time aside; values under 1e-6 in size, parameters at a bound of 0, listed apart), any change that
is not a number (named causes, units), and the table's figures in the newer file.

    python compare_shared_data.py OLD_JSON NEW_JSON
"""

import json
import sys
from pathlib import Path

TINY = 1e-6


def flat(value, path: str = "") -> dict:
    if isinstance(value, dict):
        return {k: v for key, item in value.items() for k, v in flat(item, f"{path}/{key}").items()}
    if isinstance(value, list):
        return {k: v for i, item in enumerate(value) for k, v in flat(item, f"{path}[{i}]").items()}
    return {path: value}


def is_number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def main() -> None:
    old, new = (json.loads(Path(path).read_text())["runs"] for path in sys.argv[1:3])
    print(f"{sys.argv[1]} against {sys.argv[2]}")
    print("runs only in one:", sorted(set(old) ^ set(new)))
    for run in old:
        before, after = flat(old[run]), flat(new[run])
        print(f"{run}: keys only in one: {sorted(set(before) ^ set(after))}")
        changes, tiny, other = [], [], []
        for key, value in before.items():
            if key.endswith("cpu_user_s") or key not in after:
                continue
            if is_number(value) and is_number(after[key]):
                if abs(value) <= TINY:
                    tiny.append((key, value, after[key]))
                elif value != after[key]:
                    changes.append((abs(after[key] - value) / abs(value), key))
            elif value != after[key]:
                other.append((key, value, after[key]))
        largest = max(changes, default=(0.0, None))
        print(f"  largest relative change: {largest[0]:.2e} ({largest[1]})")
        print(f"  changes that are not numbers: {other}")
        print(f"  values under {TINY:g} in size (before, after): {tiny}")
        print(f"  CPU: {old[run]['cpu_user_s']} -> {new[run]['cpu_user_s']} s")
        for figure in ("base_heldout_rmse", "extended_heldout_rmse", "rmse_ratio"):
            interval = new[run][figure]
            print(f"  {figure}: {interval['estimate']:.4g} [{interval['low']:.4g}, {interval['high']:.4g}]")
        print(f"  named {new[run]['named_causes']}, not identified {new[run]['not_identified']}")


if __name__ == "__main__":
    main()
