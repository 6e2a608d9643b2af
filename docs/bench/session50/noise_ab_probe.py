"""Every camsim case over master seeds: the shot-noise decision with and without the multiplicative term.

Usage: ``HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session50/noise_ab_probe.py [--cases A,B] SEED...``
Each case is rendered and calibrated exactly as ``tests/calibration/test_independent_sim.py`` does. The noise model
changes no prediction, so one run gives both decisions: "before" is the decision without condition 3's second
part (photon noise's share beside a multiplicative term), "after" the decision with it. Prints per case its kind,
both decisions, photon noise's share without and beside the multiplicative term, that term's relative sd with
its 90% interval, and the causes named besides shot_noise.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import tempfile

MULTIPLICATIVE_REASON = "the residual's variance grows with the square of the light"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("seeds", nargs="+", type=int)
    parser.add_argument("--cases", default="all", help="comma-separated camsim case names (default: all)")
    args = parser.parse_args()
    sys.path.insert(0, "tests/calibration")
    sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports
    for master in args.seeds:
        os.environ["CAMSIM_SEED"] = str(master)
        os.environ["CAMSIM_CASES"] = args.cases
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        with tempfile.TemporaryDirectory() as scratch:
            for name in sim.SELECTED:
                case = sim.CASE_BY_NAME[name]
                report = sim.run_case(name, scratch)["report"]
                noise = report["noise"]
                reasons = noise.get("reasons", [])
                after = noise.get("kept", False)
                before = after or (len(reasons) == 1 and reasons[0].startswith(MULTIPLICATIVE_REASON))
                share = noise.get("shot_share", {}).get("estimate", float("nan"))
                beside = noise.get("shot_share_beside_gain", {}).get("estimate", float("nan"))
                gain = noise.get("multiplicative_relative_sd", {})
                others = sorted(sim.named_causes(report) - {"shot_noise"})
                print(
                    f"{master} {case.name:30s} {case.kind:11s} before {'named' if before else '-':5s} after "
                    f"{'named' if after else '-':5s} share {share:.2f} beside {beside:.2f} relative sd "
                    f"{gain.get('estimate', float('nan')):.3f} [{gain.get('low', float('nan')):.3f}, "
                    f"{gain.get('high', float('nan')):.3f}] others {others}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
