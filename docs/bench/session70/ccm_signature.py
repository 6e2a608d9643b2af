"""Is a colour correction matrix visible in the laser capture alone? For camsim's laser blinding cases drawn with
and without a matrix (the same draws otherwise), and for the shared measured captures: among the capture's lit,
unclipped beam pixels (the laser's channel stored at >= 128, not every channel at >= 250), the share whose fainter
channels are stored at <= 2 (a matrix with negative off-diagonals pushes a narrowband laser's faint raw channels
below 0, a camera without one stores them in proportion).

Usage: ``PYTHONPATH=.:tests/calibration:tests python docs/bench/session70/ccm_signature.py [--shared DIR] SEED...``
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path

import numpy as np
import torch
from PIL import Image

from lerobot_phantom.calibration.frame_models.laser_blinding import faint_channels_at_zero

CASES = (
    "blinding_null",
    "blinding_saturation",
    "blinding_auto_exposure",
    "blinding_halo",
    "blinding_speckle_unnamed",
)


def signature(pattern: np.ndarray) -> tuple[str, int, float, float]:
    """(laser channel, lit beam pixels, share with a faint channel at 0, median faintest channel there), the counts
    by the package's own check (``faint_channels_at_zero``)."""
    lin = (pattern.astype(float) / 255.0) ** 2.2
    laser = int(lin.reshape(-1, 3).sum(0).argmax())
    lit, at_zero = faint_channels_at_zero(torch.tensor(pattern).permute(2, 0, 1).double() / 255.0, laser)
    if lit == 0:
        return "rgb"[laser], 0, float("nan"), float("nan")
    others = [c for c in range(3) if c != laser]
    lit_mask = (pattern[..., laser] >= 128) & (pattern.min(-1) < 250)
    return "rgb"[laser], lit, at_zero / lit, float(np.median(pattern[..., others].min(-1)[lit_mask]))


def main() -> None:
    args = sys.argv[1:]
    if args[:1] == ["--shared"]:
        for path in sorted(Path(args[1]).glob("*.png")):
            channel, n, share, median = signature(np.asarray(Image.open(path).convert("RGB")))
            print(
                f"shared {path.name}: laser {channel}, {n} lit beam px, faint<=2 {share:.3f}, median {median:.0f}"
            )
        args = args[2:]
    for master in [int(s) for s in args]:
        os.environ["CAMSIM_SEED"] = str(master)
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        for name in CASES:
            case = sim.CASE_BY_NAME[name]
            row = []
            for ccm in ("0", "1"):
                os.environ["CAMSIM_CCM"] = ccm
                _seed, rng, camera = sim.case_camera(case)
                pattern = case.render(rng, camera)[0].pattern
                channel, n, share, median = signature(pattern)
                row.append(
                    f"{'ccm' if ccm == '1' else 'none'}: {channel} {n:5d} px {share:.3f} med {median:3.0f}"
                )
            print(f"{master} {name:26s} {camera.tone:7s} | " + " | ".join(row), flush=True)


if __name__ == "__main__":
    main()
