"""How often the drifting-recording test's camera draw (``test_stripes.draw_camera(rng([seed, 6]), "interior")``)
has a shortest exposure whose window, wholly lit, collects less than the threshold's light, so that no row is ever
lit and the test failed before checking anything (session 61, STRIPES_SEED=3893586369).

``STRIPES_SEED=1 PYTHONPATH=. python docs/bench/session61/shortest_exposure_unlit.py`` from a checkout's root."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path.cwd() / "tests" / "calibration"))
sys.path.insert(1, str(Path.cwd() / "tests"))

import test_stripes

DRAWS = 20000


def main() -> None:
    unlit = []
    for seed in range(DRAWS):
        camera = test_stripes.draw_camera(np.random.default_rng([seed, 6]), "interior")
        window = camera["exposures_us"][0] * 1e-6 + camera["offset"]
        unlit.append(window <= camera["threshold_grey"] / camera["gain"])
    print(
        f"camera draws (seeds 0-{DRAWS - 1}) whose shortest exposure lights no row: {sum(unlit)} of {DRAWS}"
    )
    camera = test_stripes.draw_camera(np.random.default_rng([3893586369, 6]), "interior")
    window = camera["exposures_us"][0] * 1e-6 + camera["offset"]
    needed = camera["threshold_grey"] / camera["gain"]
    print(f"STRIPES_SEED=3893586369: window {window * 1e6:.1f} us, light needed {needed * 1e6:.1f} us")


if __name__ == "__main__":
    main()
