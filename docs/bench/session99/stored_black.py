"""Share of a camsim case draw's stored pixels with a channel at black (0 or 1 grey level) in its clean frames,
patterns and attacked frames, with the camera's colour correction matrix (``CAMSIM_CCM=1``) or without. Usage:
``[CAMSIM_CCM=1] CAMSIM_SEED=1 PYTHONPATH=.:tests/calibration:tests python docs/bench/session99/stored_black.py CASE
CASE_SEED``."""

from __future__ import annotations

import sys

import numpy as np
import test_independent_sim as sim


def main() -> None:
    name, seed = sys.argv[1], int(sys.argv[2])
    case = sim.CASE_BY_NAME[name]
    _, rng, camera = sim.case_camera(case, seed)
    pairs = case.render(rng, camera)
    matrix = None if camera.ccm is None else np.round(camera.ccm, 3).tolist()
    print(f"{name}, case seed {seed}: tone {camera.tone}, matrix {matrix}")
    for kind in ("clean", "pattern", "attacked"):
        frames = np.stack([getattr(p, kind) for p in pairs])
        at_black = frames <= 1
        print(
            f"  {kind}: pixels with a channel at black {at_black.any(-1).mean():.3f}, "
            f"channels at black {at_black.mean():.3f}"
        )


if __name__ == "__main__":
    main()
