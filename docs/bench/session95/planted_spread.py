"""camsim's colour-correcting auto-exposure draws: the frames' planted exposure spread (the sample deviation, over a
draw's eight pairs, of the log of each clean frame's exposure over the laser capture's, session 68's
``exposure_oracle.render``) beside the ``exposure_spread`` each batch run wrote.

Usage: ``CAMSIM_CCM=1 CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python
docs/bench/session95/planted_spread.py OUT[,OUT...] MASTER_SEED...`` (``OUT``: ``camsim_core_batch.sh`` folders
holding ``bt_SEED``).
"""

import glob
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session68"))
from exposure_oracle import render


def written_spread(out: str, master: int) -> str:
    reports = glob.glob(f"{out}/bt_{master}/camsim0/*/out/report.json")
    params = json.loads(Path(reports[0]).read_text())["extended"]["params"]
    return f"{params['exposure_spread']:.3f}" if "exposure_spread" in params else "none"


outs = sys.argv[1].split(",")
print(f"# master seed, planted spread (log sd over 8 pairs), written exposure_spread in {', '.join(outs)}")
for master in map(int, sys.argv[2:]):
    with tempfile.TemporaryDirectory() as tmp:
        _, _, ratio, _ = render("blinding_auto_exposure", master, Path(tmp))
    planted = float(np.log(ratio).std(ddof=1))
    print(master, f"planted {planted:.3f}", "written", " ".join(written_spread(out, master) for out in outs))
