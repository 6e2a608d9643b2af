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


def noiseless_sensor(camsim):
    """camsim's ``sensor`` drawing the same shot and read noise from the generator (so every later draw of the
    case is unchanged) and leaving it out of the frame."""

    def sensor(irradiance, exposure, cam, rng, *, extra_exposure=None):
        signal = exposure * irradiance
        if extra_exposure is not None:
            signal = signal + extra_exposure
        electrons = camsim.mosaic(signal) * cam.full_well_e
        rng.poisson(np.clip(electrons, 0, 50 * cam.full_well_e))
        rng.normal(0.0, cam.read_noise_e, electrons.shape)
        levels = 2**cam.adc_bits - 1
        code = np.clip(electrons / cam.full_well_e, 0.0, 1.0) * cam.well_share_of_adc
        return np.round(code * levels) / levels

    return sensor


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
        camsim.sensor = noiseless_sensor(camsim)
    for master, sim, case, seed, rng, camera in case_draws(args.case, args.seeds):
        if args.pairs is not None:
            sim.N_PAIRS = args.pairs
        render_and_calibrate(args.out, args.case, master, case, seed, rng, camera)


if __name__ == "__main__":
    main()
