"""Two camsim matrix runs of the same master seeds (``camsim_core_batch.sh`` output folders), before and after
``identify.unmeasured_params``: per case, the parameters the later run reports as not measured, and whether the
identified effects and the held-out RMSE changed.

Usage: ``python docs/bench/session81/unmeasured_scan.py OLD_OUTDIR NEW_OUTDIR``
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def reports(outdir: Path) -> dict[tuple[str, str], dict]:
    return {
        (path.parts[-5].removeprefix("bt_"), path.parts[-3]): json.loads(path.read_text())
        for path in sorted(outdir.glob("bt_*/camsim*/*/out/report.json"))
    }


def unmeasured(report: dict) -> list[str]:
    """Parameters of the written models and of every judged effect whose interval is marked not measured."""
    names = set()
    for part in ("base", "extended"):
        names |= {
            f"{part}:{k}" for k, v in report[part]["param_intervals"].items() if v.get("measured") is False
        }
    for result in report["identification"]:
        names |= {
            f"{result['effect']}:{k}"
            for k, v in result.get("intervals", {}).items()
            if v.get("measured") is False
        }
    return sorted(names)


def main() -> None:
    old, new = (reports(Path(a)) for a in sys.argv[1:3])
    common = sorted(set(old) & set(new))
    changed = flagged = 0
    for key in common:
        a, b = old[key], new[key]
        same_effects = a["extended"]["effects"] == b["extended"]["effects"]
        rmse_a, rmse_b = a["extended"]["heldout_rmse"], b["extended"]["heldout_rmse"]
        names = unmeasured(b)
        changed += not same_effects
        flagged += bool(names)
        if names or not same_effects or abs(rmse_a - rmse_b) > 1e-9 * max(abs(rmse_a), 1.0):
            print(
                f"{key[0]} {key[1]}: effects {a['extended']['effects']} -> {b['extended']['effects']}; held-out "
                f"RMSE {rmse_a:.6g} -> {rmse_b:.6g}; not measured: {', '.join(names) or 'none'}"
            )
    print(
        f"{len(common)} cases in both runs ({len(set(old) ^ set(new))} in one only); identified effects changed on "
        f"{changed}; a parameter reported as not measured on {flagged}"
    )


if __name__ == "__main__":
    main()
