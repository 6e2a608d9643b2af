"""One camsim case on given master seeds, as ``session64/run_camsim_case.py`` renders and calibrates it, with the
draw changed in one stated way: ``--noiseless`` keeps every draw of the case (scene, camera, pattern, intensities:
the generator takes the same numbers) but writes each capture without its photon and read noise; ``--pairs N``
renders N pairs instead of the test's eight, on the same camera (the pairs themselves are another draw: the case
stratifies its intensities over however many pairs it renders).

Usage: ``[CAMSIM_CCM=1] PYTHONPATH=. python docs/bench/session67/run_camsim_variant.py CASE OUTDIR SEED...
[--noiseless] [--pairs N]`` (OUTDIR/bt_SEED must not exist)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session64"))
from camsim_case_cameras import case_draws
from run_camsim_case import render_and_calibrate


class Noiseless:
    """A generator that draws camsim's shot and read noise as the real one does (so every later draw of the case is
    unchanged) and hands back their means: Poisson counts at their expectation, read noise 0."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng

    def poisson(self, lam):
        self.rng.poisson(lam)
        return np.asarray(lam, dtype=float)

    def normal(self, loc=0.0, scale=1.0, size=None):
        self.rng.normal(loc, scale, size)
        return np.full(size, loc, dtype=float)


def noiseless_sensor(sensor):
    """camsim's own ``sensor``, fed a :class:`Noiseless` generator."""

    def quiet(irradiance, exposure, cam, rng, **kwargs):
        return sensor(irradiance, exposure, cam, Noiseless(rng), **kwargs)

    return quiet


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("case")
    parser.add_argument("out", type=Path)
    parser.add_argument("seeds", type=int, nargs="+")
    parser.add_argument("--noiseless", action="store_true")
    parser.add_argument("--pairs", type=int, default=None)
    args = parser.parse_args()
    import camsim

    if args.noiseless:
        camsim.sensor = noiseless_sensor(camsim.sensor)
    for master, sim, case, seed, rng, camera in case_draws(args.case, args.seeds):
        if args.pairs is not None:
            sim.N_PAIRS = args.pairs
        render_and_calibrate(args.out, args.case, master, case, seed, rng, camera)


if __name__ == "__main__":
    main()
