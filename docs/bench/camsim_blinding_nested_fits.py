"""Nested laser blinding models fitted to one camsim case's fit pairs (the CLI's split), each warm-started from the
previous one: the parameters behind a selection path. Usage: ``PYTHONPATH=. python
docs/bench/camsim_blinding_nested_fits.py PAIRS_DIR CASE_SEED`` (a case's ``pairs`` folder under a camsim run's
basetemp, and the case seed its report was calibrated with)."""

import sys
from pathlib import Path

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames

folder = Path(sys.argv[1])
seed = int(sys.argv[2]) % 2**31
prob = BlindingFrames(load_pairs(folder, max_side=128), seed)
fit_items, held = seeded_split(prob.n_items, 0.2, seed)
prev = None
for eff in [
    ["linear_light_saturation"],
    ["linear_light_saturation", "tone_shoulder"],
    ["linear_light_saturation", "tone_shoulder", "halo_power_law"],
    ["linear_light_saturation", "tone_shoulder", "halo_power_law", "sensor_gamma"],
    ["linear_light_saturation", "halo_power_law"],
    ["linear_light_saturation", "halo_power_law", "sensor_gamma"],
]:
    f = prob.fit(frozenset(eff), fit_items, prev if prev and prev.effects <= frozenset(eff) else None)
    prev = f
    print(
        "+".join(eff),
        "fit",
        round(prob.rmse(f, fit_items), 3),
        "held",
        round(prob.rmse(f, held), 3),
        {k: round(v, 3) for k, v in f.params.items()},
    )
