"""camsim's blinding_halo case with the capture's dark-room light changed: as drawn, uniform at its mean, or none
(the rng draws stay the same); prints what the report names. usage: halo_dark_variants.py ROOT SEED..."""

import importlib
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
sys.path.insert(
    1, str(Path(__file__).resolve().parents[3] / "tests")
)  # tests/sampling.py, which the case selection imports
import camsim as cs

REAL = cs.ambient_light
root = sys.argv[1]
for master in [int(s) for s in sys.argv[2:]]:
    for variant in ("drawn", "uniform", "none"):
        os.environ["CAMSIM_SEED"] = str(master)
        sys.modules.pop("test_independent_sim", None)
        t = importlib.import_module("test_independent_sim")
        t.run_case.cache_clear()
        calls = []

        def ambient(rng, h, w, variant=variant, calls=calls):
            light = REAL(rng, h, w)
            calls.append(1)
            if len(calls) == 1 and variant != "drawn":  # the first call is the capture's dark room
                return (
                    np.broadcast_to(light.mean(axis=(0, 1)), light.shape).copy()
                    if variant == "uniform"
                    else np.zeros_like(light)
                )
            return light

        cs.ambient_light = ambient
        case = t.CASE_BY_NAME["blinding_halo"]
        r = t.run_case("blinding_halo", f"{root}/{master}_{variant}")
        named = t.named_causes(r["report"])
        print(
            master,
            variant,
            r["camera"].tone,
            sorted(r["report"]["extended"]["effects"]),
            "unplanted",
            sorted(named - case.planted - t.tolerated(case, r["camera"])),
            "log10_gain",
            round(r["report"]["extended"]["params"].get("log10_gain", float("nan")), 3),
            flush=True,
        )
        cs.ambient_light = REAL
