"""Where a blur's dwell lies between a constant-speed sweep and a sinusoid (``BlurFrames.dwell_share``, the rule that
a resonance turns): per camsim blur case and master seed, the case's frames are rendered as the test renders them,
the resonance (``sinusoidal_motion``, alone and with ``sensor_gamma``) is fitted on the calibration's fit pairs, and
the dwell share that best fits them (0 uniform, 1 arcsine) is printed with the rule's verdict (``DWELL_SHARE_FLOOR``).

Usage: ``PYTHONPATH=. python docs/bench/session84/dwell_share.py CASE[,CASE...] SEED...``
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session83"))
from across_share import each_case_draw, print_per_model

from lerobot_phantom.calibration.frame_models.ultrasound_blur import DWELL_SHARE_FLOOR


def dwell_verdict(problem, fit, items) -> str:
    """The dwell share that best fits ``items`` on ``fit``'s path, and the rule's verdict on it."""
    share = problem.dwell_share(fit, items)
    return f"dwell {share:.3f} ({'withdrawn' if share < DWELL_SHARE_FLOOR else 'turns'})"


def print_dwell(label: str, problem, items, _camera) -> None:
    """Fit each of ``MODELS`` on ``items`` and print its path's length, the best-fitting dwell and the verdict."""
    print_per_model(label, problem, items, dwell_verdict)


def main() -> None:
    each_case_draw(print_dwell, f"floor {DWELL_SHARE_FLOOR}")


if __name__ == "__main__":
    main()
