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


def render_and_calibrate(out: Path, name: str, master: int, case, seed: int, rng, camera) -> None:
    """Render one drawn case into ``OUTDIR/bt_SEED/camsim0/CASE/pairs``, calibrate it as the test does, print the
    named effects and the calibration's time."""
    import camsim

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


def main() -> None:
    name, out, seeds = sys.argv[1], Path(sys.argv[2]), [int(s) for s in sys.argv[3:]]
    for master, _sim, case, seed, rng, camera in case_draws(name, seeds):
        render_and_calibrate(out, name, master, case, seed, rng, camera)


if __name__ == "__main__":
    main()
