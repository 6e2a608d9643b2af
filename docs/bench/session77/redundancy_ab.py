"""A camsim case before and after rule 2's test of the selected model without each effect (session 77), master seed
by master seed: the camera's tone curve, the case's verdict (``test_independent_sim.passes``), the named causes, the
unplanted ones and the written model's held-out RMSE each side, and after it what was withdrawn as redundant (with
the interval of the ratio of the model without it that showed it) and each written effect's ratio without it.

Usage: ``PYTHONPATH=. python docs/bench/session77/redundancy_ab.py CASE BEFORE_OUT AFTER_OUT`` (each OUT in
``session64/run_camsim_case.py``'s layout; the seeds are those both hold)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session76"))
from camsim_case_cameras import case_draws
from pattern_record_ab import report, seeds_both_hold

SHOWN = re.compile(r"error ratio of ([\d.]+) \(90% interval ([\d.]+)-([\d.]+)\).*hold what it brought")


def main() -> None:
    case, before, after = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    seeds = seeds_both_hold(case, before, after)
    passed, unplanted = {"before": 0, "after": 0}, {"before": 0, "after": 0}
    for master, sim, _case, _seed, _rng, camera in case_draws(case, seeds):
        spec = sim.CASE_BY_NAME[case]
        line = [f"{master} {case} ({camera.tone})"]
        for side, out in (("before", before), ("after", after)):
            rep = report(out, master, case)
            verdict = sim.passes(spec, rep, camera)
            named = sim.named_causes(rep)
            extra = sorted(named - spec.planted - sim.tolerated(spec, camera))
            passed[side] += verdict
            unplanted[side] += bool(extra)
            line.append(
                f"{side}: {'pass' if verdict else 'MISS'} {sorted(named)}, unplanted {extra or 'none'}, "
                f"held-out {rep['extended']['heldout_rmse']:.2f}"
            )
        shown = [
            f"{w['effect']} in pass {w['pass']} ({m.group(1)} [{m.group(2)}, {m.group(3)}])"
            for w in rep["selection"].get("withdrawn", [])
            for m in [SHOWN.search(" ".join(w["reasons"]))]
            if m
        ]
        kept = [
            f"{r['effect']} {r['ratio_without']['estimate']:.3f} [{r['ratio_without']['low']:.3f}, "
            f"{r['ratio_without']['high']:.3f}]"
            for r in rep["identification"]
            if r.get("ratio_without") and r["identified"]
        ]
        line.append(
            f"withdrawn as redundant: {', '.join(shown) or 'none'}; written, without each: {', '.join(kept)}"
        )
        print("; ".join(line), flush=True)
    n = len(seeds)
    print(
        f"passing: before {passed['before']} of {n}, after {passed['after']} of {n}; an unplanted cause named: "
        f"before {unplanted['before']} of {n}, after {unplanted['after']} of {n}"
    )


if __name__ == "__main__":
    main()
