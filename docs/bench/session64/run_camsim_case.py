"""One camsim case on given master seeds, rendered and calibrated exactly as ``test_independent_sim.run_case`` does,
by this checkout's package, into the layout of ``camsim_core_batch.sh`` (``OUTDIR/bt_SEED/camsim0/CASE/``), without
the test file's other tests. Usage: ``PYTHONPATH=. python docs/bench/session64/run_camsim_case.py CASE OUTDIR
SEED...`` (OUTDIR/bt_SEED must not exist)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main() -> None:
    name, out, seeds = sys.argv[1], Path(sys.argv[2]), [int(s) for s in sys.argv[3:]]
    import camsim

    for master, _sim, case, seed, rng, camera in case_draws(name, seeds):
        folder = out / f"bt_{master}" / "camsim0" / name
        folder.mkdir(parents=True)
        camsim.write_pairs(folder / "pairs", case.render(rng, camera))
        began = time.perf_counter()
        report = calibrate(
            CalibrateConfig(
                attack=case.attack, measured=str(folder / "pairs"), out=str(folder / "out"), seed=seed % 2**31
            )
        )
        print(
            f"{master} {name} (case seed {seed}): {report['extended']['effects']} {time.perf_counter() - began:.1f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
