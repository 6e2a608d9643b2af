"""Wall time of light projection calibrations, and their report.json, for one checkout's package.

usage: python projection_memo_timing.py REPO OUTDIR [CAMSIM_CASE ...]
Calibrates the hidden-effects projection case (additive_light + channel_crosstalk, seed 21) and the named camsim
cases at master seed 7 with REPO's package and tests, writing each report under OUTDIR; run it for two checkouts one
after the other (never side by side on two cores) and compare the report.json files byte for byte but the input path.
"""

import importlib
import os
import sys
import time
from pathlib import Path

repo, out = sys.argv[1], Path(sys.argv[2])
sys.path.insert(0, f"{repo}/tests/calibration")
sys.path.insert(0, repo)
os.environ["CAMSIM_SEED"] = "7"
# imported after the checkout is put first on the path, so that its package and tests are the ones timed
kit = importlib.import_module("calibration_testkit")
cli = importlib.import_module("lerobot_phantom.calibration.cli")
assert cli.__file__.startswith(repo), cli.__file__
CalibrateConfig, calibrate = cli.CalibrateConfig, cli.calibrate
t = importlib.import_module("test_independent_sim")
(out / "hidden" / "m").mkdir(parents=True, exist_ok=True)
kit.RENDERERS["light_projection"](out / "hidden" / "m", {"additive_light", "channel_crosstalk"}, 21)
t0 = time.perf_counter()
calibrate(
    CalibrateConfig(
        attack="light_projection",
        measured=str(out / "hidden" / "m"),
        out=str(out / "hidden" / "out"),
        seed=21,
    )
)
print(f"hidden additive+crosstalk: {time.perf_counter() - t0:.1f} s", flush=True)
for name in sys.argv[3:]:
    t0 = time.perf_counter()
    r = t.run_case(name, str(out))
    print(
        f"{name}: {time.perf_counter() - t0:.1f} s effects {r['report']['extended']['effects']}", flush=True
    )
