"""The blinding frame model's fitted parameters on camsim's colour-correcting halo draw (``CAMSIM_CCM=1``, case seed
1835569645) for one effect set, as JSON: run at two packages, the same line says the fit did not move.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=TREE:TREE/tests/calibration:TREE/tests python docs/bench/session92/frame_model_params.py``
"""

import json
import os
import tempfile
from pathlib import Path

os.environ["CAMSIM_CCM"] = "1"

import test_independent_sim as sim

EFFECTS = frozenset({"linear_light_saturation", "halo_power_law", "colour_correction", "tone_shoulder"})

with tempfile.TemporaryDirectory() as tmp:
    problem, fit_items, _ = sim.drawn_split("blinding_halo", 1835569645, Path(tmp))
    print(json.dumps(problem.fit(EFFECTS, fit_items).params, sort_keys=True))
