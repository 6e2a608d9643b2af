"""How much of a colour-correcting camera's saturated laser core its capture's fainter channels still measure:
camsim's ``blinding_auto_exposure`` draws with a matrix (``CAMSIM_CCM=1``) at the master seeds given, each draw's
laser capture read as the calibration reads it. Within the laser channel's white core (stored >= 250 of 255), the
share of pixels where a fainter channel stores 3-252 (neither pushed to 0 by the matrix nor clipped), and the
range of the laser's light over the core's edge those pixels span if the fainter channel were read through the
camera's own matrix and the laser's colour (camsim's truths, an oracle reading).

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python docs/bench/session93/core_in_faint_channels.py
MASTER_SEED...``
"""

import os
import sys
import tempfile
from pathlib import Path

os.environ["CAMSIM_CCM"] = "1"

import test_independent_sim as sim

from lerobot_phantom.calibration.frame_models import laser_blinding as model

CASE = sim.CASE_BY_NAME["blinding_auto_exposure"]

for master in map(int, sys.argv[1:]):
    sim.MASTER_SEED = master
    seed = sim.case_seed(CASE)
    with tempfile.TemporaryDirectory() as tmp:
        problem, _, _ = sim.drawn_split(CASE.name, seed, Path(tmp))
        pattern = 255.0 * problem.pairs[0].pattern
        channel = problem.laser_channel
        white = pattern[channel] >= 250
        fainter = [c for c in range(3) if c != channel]
        measured = [(pattern[c] >= 3) & (pattern[c] <= 252) & white for c in fainter]
        either = measured[0] | measured[1]
        shares = ", ".join(
            f"{model.CHANNELS[c]} {int(m.sum())}" for c, m in zip(fainter, measured, strict=True)
        )
        print(
            f"{master} case seed {seed}: laser {model.CHANNELS[channel]}, white core {int(white.sum())} px, "
            f"a fainter channel measured in {int(either.sum())} of them ({shares})"
        )
