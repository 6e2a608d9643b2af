"""One hidden-effects case of ``tests/calibration/test_hidden_effects.py``, timed, its report written as JSON.

Renders the test kit's frame pairs for ATTACK with the PLANTED effects (``+``-joined) at SEED, runs the
calibration with the test's options (default bootstrap, ``seed=SEED``), prints the seconds the calibration took
and the named effects, and writes report.json's content to OUT (compare two checkouts' outputs with
``python -c`` and ``json``; only ``input.path`` differs between runs of the same code).

Usage (from a checkout; it imports that checkout's package):
``HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session36/hidden_stripe_case.py laser_color_strip exposure_overlap 62 OUT.json``
"""

import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, "tests/calibration")

import calibration_testkit as kit

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate


def main(attack: str, planted: set[str], seed: int, out: Path) -> None:
    scratch = Path(tempfile.mkdtemp())
    measured = scratch / "measured"
    measured.mkdir()
    kit.RENDERERS[attack](measured, planted, seed)
    began = time.time()
    report = calibrate(
        CalibrateConfig(attack=attack, measured=str(measured), out=str(scratch / "out"), seed=seed)
    )
    print(
        attack,
        sorted(planted),
        seed,
        f"calibrate {time.time() - began:.1f} s",
        "named",
        report["extended"]["effects"],
        flush=True,
    )
    out.write_text(json.dumps(report, indent=1, sort_keys=True, default=str))


if __name__ == "__main__":
    main(sys.argv[1], set(sys.argv[2].split("+")), int(sys.argv[3]), Path(sys.argv[4]))
