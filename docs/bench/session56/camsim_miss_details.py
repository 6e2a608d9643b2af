"""The figures behind each case that misses issue 12's rules in ``camsim_core_batch.sh`` runs (the cases
``camsim_acceptance.py`` lists): per case, the selection steps' scores and the best group holding a missed planted
effect; the named effects' fitted intervals and validation ratios; the photon-noise reading beside the camera's own
(2 x 255 / full well, the pair difference's photon gain in linear grey levels before demosaicing); the residual
structure tests' low ends.

Usage: ``CAMSIM_CASES=all PYTHONPATH=. python docs/bench/session56/camsim_miss_details.py OUTDIR...`` from the
repository root.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1]))

from camsim_named_causes import case_results


def main() -> None:
    for out in sys.argv[1:]:
        for seed, _sim, case, report, judged in case_results(Path(out)):
            if judged["passed"]:
                continue
            camera = judged["camera"]
            print(
                f"{case.name} (seed {seed}, {case.kind}, {camera.tone} camera): named {sorted(judged['named'])}"
            )
            missed = case.planted - judged["named"]
            for step in report["selection"]["steps"]:
                tried = {g: v for g, v in (step.get("tried") or {}).items() if any(m in g for m in missed)}
                best = min(tried.items(), key=lambda item: item[1], default=None)
                print(
                    f"  step {step['effects']}: {step['validation_error']:.3f}; best group with {sorted(missed)}: {best}"
                )
            for result in report["identification"]:
                ratio = result.get("validation_ratio") or {}
                print(
                    f"  {result['effect']}: identified {result['identified']}, validation ratio "
                    f"{ratio.get('estimate', float('nan')):.3f} [{ratio.get('low', float('nan')):.3f}, "
                    f"{ratio.get('high', float('nan')):.3f}]"
                )
            intervals = report["extended"]["param_intervals"]
            for name in ("gamma",):
                if name in intervals:
                    i = intervals[name]
                    print(f"  {name}: {i['estimate']:.3f} [{i['low']:.3f}, {i['high']:.3f}]")
            noise = report.get("noise", {})
            if noise.get("kept"):
                gain, share = noise["intervals"]["shot_gain_grey"], noise["shot_share"]
                print(
                    f"  shot_noise: gain {gain['estimate']:.3f} [{gain['low']:.3f}, {gain['high']:.3f}], share "
                    f"{share['estimate']:.2f} [{share['low']:.2f}, {share['high']:.2f}]; the camera's photon gain "
                    f"2 x 255 / {camera.full_well_e:.0f} e- = {2 * 255 / camera.full_well_e:.4f}"
                )
            structure = report["unexplained_structure"]
            print(f"  structure remains: {structure['structure_remains']}")
            for test in structure.get("tests", []):
                if "interval" in test:
                    print(
                        f"    {test['variable']}: {test.get('statistic')} low end {test['interval']['low']:.4f}, "
                        f"significant {test['significant']}"
                    )
            print(
                f"  held-out: base {report['base']['heldout_rmse']:.2f}, written {report['extended']['heldout_rmse']:.2f}"
            )


if __name__ == "__main__":
    main()
