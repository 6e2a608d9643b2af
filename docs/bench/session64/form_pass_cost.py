"""What repeating a selection pass costs: camsim cases calibrated by this checkout's package, with the process CPU
seconds of the whole calibration and of each forward selection pass in it (``core.forward_select``, timed by a
wrapper; the first call of each ``select_forms`` is the first pass, a second one the repeat without a simpler
form). Where the repeat is not taken, its share is what a package without repeats saves; where it is taken, the
written model differs too (identifying it costs what its size costs), so the share is the selection's part only.

Usage: ``PYTHONPATH=. python docs/bench/session64/form_pass_cost.py CASE MASTER_SEED...``
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path
from unittest import mock

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration import core
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main() -> None:
    name, seeds = sys.argv[1], [int(s) for s in sys.argv[2:]]
    import camsim

    forward_select = core.forward_select
    passes: list[float] = []

    def timed(*args, **kwargs):
        began = time.process_time()
        result = forward_select(*args, **kwargs)
        passes.append(time.process_time() - began)
        return result

    for master, _sim, case, seed, rng, camera in case_draws(name, seeds):
        passes.clear()
        with tempfile.TemporaryDirectory() as scratch, mock.patch.object(core, "forward_select", timed):
            camsim.write_pairs(Path(scratch) / "pairs", case.render(rng, camera))
            began = time.process_time()
            report = calibrate(
                CalibrateConfig(
                    attack=case.attack,
                    measured=str(Path(scratch) / "pairs"),
                    out=str(Path(scratch) / "out"),
                    seed=seed % 2**31,
                )
            )
            total = time.process_time() - began
        repeats = report["selection"]["form_passes"]
        repeat_seconds = sum(passes[1:]) if repeats else 0.0
        print(
            f"{master} {name} ({camera.tone}): calibration {total:.1f} s CPU, selection passes "
            f"{[round(t, 1) for t in passes]} s; repeats {[(r['without'], r['taken']) for r in repeats]}; the "
            f"repeat's share {repeat_seconds / total:.2f} (without it {total - repeat_seconds:.1f} s, ratio "
            f"{total / (total - repeat_seconds):.2f})",
            flush=True,
        )


if __name__ == "__main__":
    main()
