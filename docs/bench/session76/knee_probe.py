"""What the decoding of an emitted pattern does to the fitted shoulder and reflectance: fits, in-sample on every pair
of one camsim light projection draw (the package's pixel sample), the case's planted form (additive light,
cross-talk, the shoulder, light spread) without and with the reflectance term, the pattern taken as captured (the
camera's fitted curve decodes it, as the package did before session 76) and as emitted (the fitted projector gamma).

Usage: ``PYTHONPATH=. python docs/bench/session76/knee_probe.py PAIRS_DIR`` (the pairs of
``session64/run_camsim_case.py``; camsim's projector: light = frame ** 2.2, reflectance floor 0)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames

FORM = ("additive_light", "channel_crosstalk", "tone_shoulder", "light_spread")


def main() -> None:
    pairs = load_pairs(Path(sys.argv[1]), max_side=CalibrateConfig().max_side)
    items = np.arange(len(pairs))
    for record in ("captured", "emitted"):
        problem = ProjectionFrames(pairs, seed=0, pattern_record=record)
        for extra in ((), ("albedo_modulation",)):
            fit = problem.fit(frozenset(FORM + extra), items)
            sse, n = problem.squared_errors(fit, items)
            shown = ", ".join(
                f"{k} {fit.params[k]:.3f}"
                for k in ("projector_gamma", "reflectance_floor", "shoulder", "shoulder_exponent")
                if k in fit.params
            )
            print(
                f"{record}, {'+'.join(FORM + extra)}: RMSE {np.sqrt(sse / n):.3f} grey levels; {shown}",
                flush=True,
            )


if __name__ == "__main__":
    main()
