"""A camsim light projection case before and after the pattern record (session 76), master seed by master seed:
the camera's tone curve, the named causes and the case's verdict (``test_independent_sim.passes``) each side, the
written model's held-out RMSE each side, and after it the fitted projector gamma (camsim's projector: 2.2) with its
interval, the reflectance floor (planted 0) and the shoulder's knee exponent where the model has them.

Usage: ``PYTHONPATH=. python docs/bench/session76/pattern_record_ab.py CASE BEFORE_OUT AFTER_OUT`` (each OUT in
``session64/run_camsim_case.py``'s layout; the seeds are those both hold)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws


def report(out: Path, master: int, case: str) -> dict:
    return json.loads((out / f"bt_{master}" / "camsim0" / case / "out" / "report.json").read_text())


def seeds_both_hold(case: str, before: Path, after: Path) -> list[int]:
    """The master seeds whose report of ``case`` both outputs hold."""
    return sorted(
        int(p.name.removeprefix("bt_"))
        for p in after.glob("bt_*")
        if (p / "camsim0" / case / "out" / "report.json").is_file()
        and (before / p.name / "camsim0" / case / "out" / "report.json").is_file()
    )


def main() -> None:
    case, before, after = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    seeds = seeds_both_hold(case, before, after)
    passed = {"before": 0, "after": 0}
    for master, sim, _case, _seed, _rng, camera in case_draws(case, seeds):
        line = [f"{master} {case} ({camera.tone})"]
        for side, out in (("before", before), ("after", after)):
            rep = report(out, master, case)
            verdict = sim.passes(sim.CASE_BY_NAME[case], rep, camera)
            passed[side] += verdict
            named = sorted(sim.named_causes(rep))
            line.append(
                f"{side}: {'pass' if verdict else 'MISS'} {named}, held-out {rep['extended']['heldout_rmse']:.2f}"
            )
        params, intervals = rep["extended"]["params"], rep["extended"]["param_intervals"]
        fitted = []
        for name in ("projector_gamma", "reflectance_floor", "shoulder_exponent", "gamma"):
            if name in params:
                span = intervals.get(name)
                fitted.append(
                    f"{name} {params[name]:.3f}"
                    + (f" [{span['low']:.3f}, {span['high']:.3f}]" if span else "")
                )
        print("; ".join(line) + "; after's " + (", ".join(fitted) or "no such parameter"))
    print(f"passing: before {passed['before']} of {len(seeds)}, after {passed['after']} of {len(seeds)}")


if __name__ == "__main__":
    main()
