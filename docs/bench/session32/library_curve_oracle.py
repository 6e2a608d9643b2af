"""Is reflectance named on camsim's filmic ``projection_crosstalk`` cases when the camera's tone curve is in the
library's own family? camsim's filmic curve (ACES on a 4x pre-gain, then sRGB) is replaced by the library's shoulder
form at its closest fit to it (shoulder 38.8, knee exponent 1.19, no display gamma: 0.48 grey levels RMS,
``camsim_session15/filmic_shoulder_fit.txt``); every other draw is the case's own. Prints the named causes (the
test's rule), the planted ones missing, the held-out RMSE and the identified parameters (cross-talk entries left out).

Usage: ``PYTHONPATH=. python docs/bench/session32/library_curve_oracle.py CASE MASTER_SEED ROOT`` from the repository
root (one master seed per process: the test module reads it at import).
"""

from __future__ import annotations

import importlib
import os
import sys
import time

import numpy as np
import torch

from lerobot_phantom.calibration.tone import shoulder_encode

sys.path.insert(0, "tests/calibration")
import camsim as cs

CLOSEST = {"shoulder": 38.8, "shoulder_exponent": 1.19}
camsim_curve = cs.tone_curve


def library_family(linear: np.ndarray, cam: cs.Camera) -> np.ndarray:
    if cam.tone != "filmic":
        return camsim_curve(linear, cam)
    return shoulder_encode(torch.from_numpy(np.clip(linear, 0.0, 1.0).astype(np.float64)), CLOSEST).numpy()


def main(name: str, seed: str, root: str) -> None:
    cs.tone_curve = library_family
    os.environ["CAMSIM_SEED"] = seed
    sim = importlib.import_module("test_independent_sim")
    started = time.process_time()
    result = sim.run_case(name, root)
    report, named = result["report"], sim.named_causes(result["report"])
    fitted = {
        k: round(v, 3)
        for item in report["identification"]
        for k, v in item["params"].items()
        if not k.startswith("crosstalk")
    }
    print(
        f"{name} {seed} library curve: named {sorted(named)} missing {sorted(sim.CASE_BY_NAME[name].planted - named)} "
        f"tone {result['camera'].tone} held-out {report['base']['heldout_rmse']:.3f} -> "
        f"{report['extended']['heldout_rmse']:.3f} cpu {time.process_time() - started:.0f} s {fitted}",
        flush=True,
    )


if __name__ == "__main__":
    main(*sys.argv[1:])
