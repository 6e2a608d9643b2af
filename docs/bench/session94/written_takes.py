"""camsim's colour-correcting auto-exposure draws calibrated by a ``camsim_core_batch.sh`` run: per draw, the written
matrix's takes, laser colour and inner core against camsim's takes (each column's mean off-diagonal, negated), and
what selection withdrew.

Usage: ``PYTHONPATH=.:tests/calibration:tests CAMSIM_SEED=0 python docs/bench/session94/written_takes.py OUT``
(``OUT``: the batch's output folder, holding ``bt_SEED``).
"""

import glob
import json
import os
import sys
from pathlib import Path

os.environ["CAMSIM_CCM"] = "1"

import numpy as np
import test_independent_sim as sim

CASE = sim.CASE_BY_NAME["blinding_auto_exposure"]
print(
    "# per draw (camsim CCM auto-exposure): the written matrix's takes, laser colour and inner core; camsim's takes "
    "(each column's mean off-diagonal, negated); selection.withdrawn"
)
for path in sorted(glob.glob(f"{sys.argv[1]}/bt_*/camsim0/*/out/report.json")):
    sim.MASTER_SEED = int(path.split("/bt_")[1].split("/")[0])
    _, _, cam = sim.case_camera(CASE, sim.case_seed(CASE))
    matrix = np.reshape(cam.ccm, (3, 3))
    takes = [round(float(-(matrix[:, j].sum() - matrix[j, j]) / 2), 3) for j in range(3)]
    report = json.loads(Path(path).read_text())
    written = {
        k: round(v, 3)
        for k, v in report["extended"]["params"].items()
        if k.startswith(("ccm", "laser_colour", "inner"))
    }
    print(
        sim.MASTER_SEED,
        "camsim takes",
        takes,
        "written",
        written,
        "withdrawn",
        report["selection"]["withdrawn"],
    )
