"""The dwell read on the library's own resonance (``test_identify.blur_pairs``: 48x64 frames of 4-pixel colour
blocks, blurred along the arcsine path (6, 3) px) with one kind of camera error added: noise of sd 0.05 or 0.1 on the
clean frames only, or camsim's Bayer mosaic and bilinear demosaic on the clean frames only or on both frames (the
attacked frame's made after its blur, as a camera makes it). Per kind, the dwell share read pixel by pixel
(``DWELL_LOWPASS_PX`` set to 0) and over ``DWELL_LOWPASS_PX``. Usage: ``CAMSIM_SEED=1 PYTHONPATH=.
python docs/bench/session98/dwell_synthetic.py`` (CAMSIM_SEED only lets the test modules import)."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
sys.path.insert(1, str(Path(__file__).resolve().parents[3] / "tests"))
import camsim
import test_identify

from lerobot_phantom.calibration.frame_models import ultrasound_blur
from lerobot_phantom.calibration.frame_models.ultrasound_blur import BlurFrames


def bayer(frame: torch.Tensor) -> torch.Tensor:
    planes = camsim.demosaic(camsim.mosaic(frame.permute(1, 2, 0).numpy()))
    return torch.from_numpy(planes).permute(2, 0, 1).contiguous()


def main() -> None:
    pairs = test_identify.blur_pairs("resonance").pairs
    generator = torch.Generator().manual_seed(1)

    def noisy(sd):
        return [
            dataclasses.replace(
                p,
                clean=(
                    p.clean + sd * torch.randn(p.clean.shape, generator=generator, dtype=torch.float64)
                ).clamp(0, 1),
            )
            for p in pairs
        ]

    kinds = {
        "as rendered": pairs,
        "clean frames' noise sd 0.05": noisy(0.05),
        "clean frames' noise sd 0.1": noisy(0.1),
        "Bayer on the clean frames": [dataclasses.replace(p, clean=bayer(p.clean)) for p in pairs],
        "Bayer on both frames": [
            dataclasses.replace(p, clean=bayer(p.clean), attacked=bayer(p.attacked)) for p in pairs
        ],
    }
    lowpass = ultrasound_blur.DWELL_LOWPASS_PX
    for kind, kind_pairs in kinds.items():
        problem = BlurFrames(kind_pairs, 0)
        items = np.arange(len(kind_pairs))
        fit = problem.fit(frozenset({"sinusoidal_motion"}), items)
        reads = []
        for sigma in (0.0, lowpass):
            ultrasound_blur.DWELL_LOWPASS_PX = sigma
            reads.append(f"over {sigma:g} px {problem.dwell_share(fit, items):.3f}")
        ultrasound_blur.DWELL_LOWPASS_PX = lowpass
        print(f"{kind}: dwell share {'; '.join(reads)}", flush=True)


if __name__ == "__main__":
    main()
