"""A colour correction matrix's sign in light projection frame pairs: added light that lowers a stored channel.
Light only adds, so without a matrix no channel of a lit pixel falls from the clean frame to the attacked one beyond
noise and compression; a matrix with negative off-diagonals takes a strongly lit raw channel's light out of the
others. Per camsim run folder (``OUT/bt_SEED/camsim0/CASE/pairs``, as ``camsim_core_batch.sh`` and
``session64/run_camsim_case.py`` write them): of the pixels the pattern lights (a channel >= 0.5 of white, pairs read
as the calibration reads them), the share with a channel stored at least 8, 16 and 32 grey levels lower in the
attacked frame than in the clean one. Usage: ``PYTHONPATH=. python docs/bench/session97/projection_ccm_signature.py
LABEL=OUT...``"""

from __future__ import annotations

import sys
from pathlib import Path

import torch

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem

FALLS = (8, 16, 32)


def main() -> None:
    for argument in sys.argv[1:]:
        label, out = argument.split("=", 1)
        for pairs in sorted(Path(out).glob("bt_*/camsim0/projection_*/pairs")):
            problem = build_problem(
                CalibrateConfig(attack="light_projection", measured=str(pairs), out="unused")
            )
            lit, fallen = 0, torch.zeros(len(FALLS))
            for pair in problem.pairs:
                where = pair.pattern.amax(0) >= 0.5
                fall = 255.0 * (pair.clean - pair.attacked).amax(0)[where]
                lit += int(where.sum())
                fallen += torch.tensor([float((fall >= f).sum()) for f in FALLS])
            shares = ", ".join(
                f">= {f}: {float(n) / max(lit, 1):.4f}" for f, n in zip(FALLS, fallen, strict=True)
            )
            print(
                f"{label} {pairs.parts[-4][3:]} {pairs.parts[-2]}: {lit} lit pixels; a channel fallen {shares}"
            )


if __name__ == "__main__":
    main()
