"""Does the library name a camsim case's planted effects when the frames carry the tone curve it assumes?

Usage: ``PYTHONPATH=. CAMSIM_SEED=0 python docs/bench/camsim_tone_oracle_case.py CASE SEED...`` from the repository
root. Each master seed renders the case exactly as ``tests/calibration/test_independent_sim.py`` does and calibrates
it twice: the frames as stored (``pairs``), and every stored image (clean, attacked, pattern) re-encoded from the
camera's own tone curve to sRGB through a 256-entry table, ``v -> sRGB(tone^-1(v))`` (``oracle``; the light in the
frames is unchanged, only its encoding is the one the library's linear-light models decode). One line per
calibration: the planted effects left unnamed, the named causes (the test's rule) and both held-out RMSEs.
"""

from __future__ import annotations

import importlib
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch
from PIL import Image

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.transforms.physics import linear_to_srgb

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports


def main() -> None:
    name = sys.argv[1]
    camsim = importlib.import_module("camsim")
    for master in sys.argv[2:]:
        os.environ["CAMSIM_SEED"] = master
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        case = sim.CASE_BY_NAME[name]
        seed, rng, camera = sim.case_camera(case)
        with tempfile.TemporaryDirectory() as scratch:
            root = Path(scratch)
            camsim.write_pairs(root / "pairs", case.render(rng, camera))
            grid = np.linspace(0.0, 1.0, 20001)
            table = np.interp(np.arange(256) / 255, camsim.tone_curve(grid, camera), grid)
            table = np.round(255 * linear_to_srgb(torch.from_numpy(table)).numpy()).astype(np.uint8)
            (root / "oracle").mkdir()
            for path in (root / "pairs").iterdir():
                target = root / "oracle" / path.name
                if path.suffix == ".png":
                    Image.fromarray(table[np.asarray(Image.open(path).convert("RGB"))]).save(target)
                else:
                    target.write_bytes(path.read_bytes())
            for kind in ("pairs", "oracle"):
                report = calibrate(
                    CalibrateConfig(
                        attack=case.attack,
                        measured=str(root / kind),
                        out=str(root / f"out_{kind}"),
                        seed=seed % 2**31,
                    )
                )
                named = sim.named_causes(report)
                print(
                    f"{master} {camera.tone} {kind} missing {sorted(case.planted - named)} named {sorted(named)} "
                    f"held {report['base']['heldout_rmse']:.2f} -> {report['extended']['heldout_rmse']:.2f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
