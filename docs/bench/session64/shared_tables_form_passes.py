"""The shared light projection tables calibrated by this checkout's package (in-process, the CLI's defaults, seed 0):
the written model, its held-out RMSE and the selection passes repeated without a simpler form
(``selection.form_passes``). Usage: ``PYTHONPATH=. python docs/bench/session64/shared_tables_form_passes.py
MEASURED_DIR`` (``../shared/measured``, third-party data not in this repository)."""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main() -> None:
    measured = Path(sys.argv[1])
    for name in ("slap_stop_sign_triples.csv", "slap_bottle_triples.csv"):
        with tempfile.TemporaryDirectory() as scratch:
            began = time.process_time()
            report = calibrate(
                CalibrateConfig(
                    attack="light_projection",
                    measured=str(measured / "projection" / name),
                    out=scratch,
                    seed=0,
                )
            )
            seconds = time.process_time() - began
        extended = report["extended"]
        print(
            f"{name}: selected {report['selection']['selected']}, written {extended['effects']}, held-out "
            f"{extended['heldout_rmse']:.3f} {extended['heldout_rmse_interval']['low']:.3f}-"
            f"{extended['heldout_rmse_interval']['high']:.3f} (base {report['base']['heldout_rmse']:.3f}); "
            f"repeats without a simpler form: {report['selection']['form_passes']}; {seconds:.0f} s CPU",
            flush=True,
        )


if __name__ == "__main__":
    main()
