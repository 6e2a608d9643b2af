"""camsim's EM colour strip cases calibrated by the package before and after 5d340f2 (values the colour map decodes
read at the sensor values they came from), side by side: per case, the named causes, the variables the held-out
structure rule reports, the low end of the variance-by-row and -by-column tests' 90% interval (bar max(0.02,
chance)) and the photon-noise decision. Reads the report.json files of ``session73/variance_probe.py`` runs.
Usage: ``python docs/bench/session74/noise_sources_ab.py BEFORE_OUT AFTER_OUT``."""

import json
import sys
from pathlib import Path


def summary(report_path: Path, tally: dict, side: str, case: str) -> str:
    report = json.loads(report_path.read_text())
    named = "+".join(sorted(x["effect"] for x in report["identification"] if x["identified"])) or "base"
    tests = report["unexplained_structure"]["tests"]
    found = ",".join(t["variable"] for t in tests if t["significant"]) or "-"
    lows = {
        t["variable"].removeprefix("variance_by_")[:3]: t["interval"]["low"]
        for t in tests
        if t["variable"].startswith("variance_by_")
    }
    noise = report["noise"].get("status", "not run")
    counts = tally.setdefault(
        (case, side), {"cases": 0, "variance_by_row": 0, "photon noise named": 0, "square of the light": 0}
    )
    counts["cases"] += 1
    counts["variance_by_row"] += "variance_by_row" in found.split(",")
    counts["photon noise named"] += noise == "identified"
    counts["square of the light"] += any(
        r.startswith("the residual's variance grows with the square")
        for r in report["noise"].get("reasons", [])
    )
    counts.setdefault("named", []).append(named)
    share = report["noise"].get("shot_share_beside_gain", {}).get("estimate", float("nan"))
    return (
        f"{named:18s} {found:44s} row {lows.get('row', float('nan')):.4f} col {lows.get('col', float('nan')):.4f} "
        f"{noise} (photon share beside the multiplicative term {share:.2f})"
    )


def main() -> None:
    before, after = Path(sys.argv[1]), Path(sys.argv[2])
    print("per case: named causes, structure variables reported, variance lows by row / column, photon noise")
    tally: dict = {}
    for path in sorted(before.glob("bt_*/camsim0/*/out/report.json")):
        relative = path.relative_to(before)
        seed, case = relative.parts[0].removeprefix("bt_"), relative.parts[2]
        print(f"{seed} {case}")
        print(f"  before {summary(path, tally, 'before', case)}")
        print(f"  after  {summary(after / relative, tally, 'after', case)}")
    print(
        "\ntally: cases; variance_by_row reported; photon noise named; photon noise held back as variance growing "
        "with the square of the light (a fluctuating light); named causes the same before and after"
    )
    for case in sorted({case for case, _ in tally}):
        b, a = tally[(case, "before")], tally[(case, "after")]
        same = sum(x == y for x, y in zip(b["named"], a["named"], strict=True))
        print(
            f"{case:28s} {b['cases']} cases; variance_by_row {b['variance_by_row']} -> {a['variance_by_row']}; "
            f"photon noise {b['photon noise named']} -> {a['photon noise named']}; square of the light "
            f"{b['square of the light']} -> {a['square of the light']}; named the same {same}"
        )


if __name__ == "__main__":
    main()
