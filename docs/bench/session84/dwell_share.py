"""Where a blur's dwell lies between a constant-speed sweep and a sinusoid (``BlurFrames.dwell_share``, the rule that
a resonance turns): per camsim blur case and master seed, the case's frames are rendered as the test renders them,
the resonance (``sinusoidal_motion``, alone and with ``sensor_gamma``) is fitted on the calibration's fit pairs, and
the dwell share that best fits them (0 uniform, 1 arcsine) is printed with the rule's verdict (``DWELL_SHARE_FLOOR``).

Usage: ``PYTHONPATH=. python docs/bench/session84/dwell_share.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session83"))
from across_share import MODELS, each_case_draw

from lerobot_phantom.calibration.frame_models.ultrasound_blur import DWELL_SHARE_FLOOR


def print_dwell(label: str, problem, items) -> None:
    """Fit each of ``MODELS`` on ``items`` and print its path's length, the best-fitting dwell and the verdict."""
    for effects in MODELS:
        fit = problem.fit(effects, items)
        began = time.perf_counter()
        share = problem.dwell_share(fit, items)
        length = float(np.hypot(fit.params["dx_ref_px"], fit.params["dy_ref_px"]))
        verdict = "withdrawn" if share < DWELL_SHARE_FLOOR else "turns"
        print(
            f"{label} {'+'.join(sorted(effects))}: path {length:.1f} px, dwell {share:.3f} ({verdict}) "
            f"({time.perf_counter() - began:.2f} s)",
            flush=True,
        )


def main() -> None:
    each_case_draw(print_dwell, f"floor {DWELL_SHARE_FLOOR}")


if __name__ == "__main__":
    main()
