"""How much camsim's planted glare tail changes the blinding_halo case's attacked frames, per master seed (session 96).

The case's own draw (camera, laser, glare, powers, intensities, scenes) rendered twice without noise, once as drawn
and once with the tail removed from the laser's spot; prints the mean absolute change of the attacked frames (grey
levels, 8-bit, after the JPEG round trip) and the share of pixels changed by more than 3 levels. Noise is dropped
in both renders (the sensor's shot and read noise draw nothing), so the scenes are not the case's exact ones, but
the two renders share every draw and differ only by the tail.

    PYTHONPATH=.:tests/calibration:tests python docs/bench/session96/halo_visibility.py SEED...
"""

from __future__ import annotations

import importlib
import os
import sys

import numpy as np


def noise_free_sensor(cs):
    def sensor(irradiance, exposure, cam, rng, *, extra_exposure=None):
        signal = exposure * irradiance
        if extra_exposure is not None:
            signal = signal + extra_exposure
        code = np.clip(cs.mosaic(signal), 0.0, 1.0) * cam.well_share_of_adc
        levels = 2**cam.adc_bits - 1
        return np.round(code * levels) / levels

    return sensor


def glare_change(seed: int) -> tuple[str, float, float]:
    os.environ["CAMSIM_SEED"] = str(seed)
    import camsim as cs
    import test_independent_sim as tis

    tis = importlib.reload(tis)
    case = tis.CASE_BY_NAME["blinding_halo"]
    original_spot, original_sensor = cs.laser_spot, cs.sensor
    cs.sensor = noise_free_sensor(cs)
    renders = []
    try:
        for keep_tail in (True, False):
            if not keep_tail:
                cs.laser_spot = lambda *a, halo, **k: original_spot(*a, halo=None, **k)
            _, rng, camera = tis.case_camera(case)
            renders.append(np.stack([p.attacked.astype(float) for p in case.render(rng, camera)]))
    finally:
        cs.laser_spot, cs.sensor = original_spot, original_sensor
    change = np.abs(renders[0] - renders[1])
    return camera.tone, float(change.mean()), float(np.mean(change > 3))


def main() -> None:
    for seed in map(int, sys.argv[1:]):
        tone, mean_change, share = glare_change(seed)
        print(
            f"master {seed}: tone {tone}, mean change {mean_change:.2f} grey levels, share > 3 levels {share:.3f}"
        )


if __name__ == "__main__":
    main()
