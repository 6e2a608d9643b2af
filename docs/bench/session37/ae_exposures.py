"""Per pair of camsim's blinding_auto_exposure case: intensity, the attacked frame's exposure over its clean frame's,
and the clean frame's exposure over the pattern capture's (the session's first)."""

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
sys.path.insert(
    1, str(Path(__file__).resolve().parents[3] / "tests")
)  # tests/sampling.py, which the case selection imports
os.environ["CAMSIM_SEED"] = sys.argv[1]
import camsim as cs
import test_independent_sim as t

calls = []
real = cs.capture


def capture(irr, cam, rng, exposure=None, **k):
    out, used = real(irr, cam, rng, exposure=exposure, **k)
    calls.append(used)
    return out, used


cs.capture = capture
case = t.CASE_BY_NAME[sys.argv[2] if len(sys.argv) > 2 else "blinding_auto_exposure"]
seed, rng, cam = t.case_camera(case)
pairs = case.render(rng, cam)
first = calls[1]  # clean0, pattern, attacked0, clean1, attacked1, ...
clean = [calls[0], *calls[3::2]]
attacked = calls[2::2]
print(f"tone {cam.tone} full_well {cam.full_well_e:.0f}")
for p, c, a in zip(pairs, clean, attacked, strict=True):
    print(
        f"intensity {p.intensity:.2f}  attacked/clean exposure {a / c:.3f}  clean/pattern exposure {c / first:.3f}  "
        f"clean mean {p.clean.mean():.1f} attacked mean {p.attacked.mean():.1f}"
    )
