"""One camsim case at a fixed case seed, its first selection step: ``python replay_case.py CASE SEED OUTDIR``.

Run from a checkout's root with ``PYTHONPATH=.``. Prints the named causes and, for each selection step, the
cross-validated RMSE and what each candidate scored.
"""

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path.cwd() / "tests" / "calibration"))
sys.path.insert(1, str(Path.cwd() / "tests"))  # tests/sampling.py, which the case selection imports
os.environ.setdefault("CAMSIM_SEED", "0")  # read by the module; the case seed is given explicitly

import test_independent_sim as sim


def main() -> None:
    name, seed, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    report = sim.run_case(name, out, seed)["report"]
    print(f"{name} case seed {seed}: named {sorted(sim.named_causes(report))}")
    for step in report["selection"]["steps"]:
        print(
            f"  step {step['effects']}: cross-validated {step['validation_error']:.4f}, tried {step['tried']}"
        )
    print(
        f"  held-out: base {report['base']['heldout_rmse']:.4f}, written {report['extended']['heldout_rmse']:.4f}"
    )


if __name__ == "__main__":
    main()
