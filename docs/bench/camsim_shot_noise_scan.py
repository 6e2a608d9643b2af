"""The independent simulator's ``truncation_shot_noise`` case over master seeds: tone curve, noise decision.

Usage: ``PYTHONPATH=. python docs/bench/camsim_shot_noise_scan.py TESTS_DIR [--tone TONE] SEED...``
TESTS_DIR holds ``test_independent_sim.py`` and ``camsim.py`` (``tests/calibration``, or a copy of them from an
older commit, to replay an older draw). Each master seed renders the case exactly as the test does (``--tone``
overrides the drawn tone curve) and calibrates it; prints the seed, the camera's tone curve, whether
``shot_noise`` is named, the noise status, photon noise's share of the modelled variance and the variance trend
(darkest vs brightest quarter of the signal, relative to the noise model) with its interval.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import os
import sys
import tempfile
from pathlib import Path

NAME = "truncation_shot_noise"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("tests_dir")
    parser.add_argument("seeds", nargs="+", type=int)
    parser.add_argument("--tone", default=None, help="override the drawn tone curve (srgb, filmic, power)")
    args = parser.parse_args()
    sys.path.insert(0, args.tests_dir)
    sys.path.insert(
        1, str(Path(args.tests_dir).parent)
    )  # tests/sampling.py, which the case selection imports
    for master in args.seeds:
        os.environ["CAMSIM_SEED"] = str(master)
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        if args.tone:
            # a fixed tone replaces the drawn one (a drawn tone then no longer takes its draw from the case's rng)
            case = sim.CASE_BY_NAME[NAME]
            sim.CASE_BY_NAME[NAME] = dataclasses.replace(case, camera={**case.camera, "tone": args.tone})
        with tempfile.TemporaryDirectory() as scratch:
            result = sim.run_case(NAME, scratch)  # renders and calibrates exactly as the test does
        noise, camera = result["report"]["noise"], result["camera"]
        trend = noise["variance_trend"]
        tone = camera.tone + (f" {camera.tone_gamma:.2f}" if camera.tone == "power" else "")
        print(
            f"master {master} case seed {result['seed']}: {tone}, shot_noise "
            f"{'named' if noise['kept'] else 'not named'} ({noise['status']}), photon share "
            f"{noise['shot_share']['estimate']:.2f}, variance trend {trend['estimate']:.2f} "
            f"[{trend['low']:.2f}, {trend['high']:.2f}]",
            flush=True,
        )


if __name__ == "__main__":
    main()
