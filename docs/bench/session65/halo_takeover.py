"""Where the fitted glare stands against the capture's beam just outside the region the capture measured, in a camsim
blinding_halo draw: linear light + shoulder + halo fitted on the calibration's fit pairs; over the probe pixels the
capture did not measure, per radius bin (reference pixels), the median of glare / (beam continued x gain) in the
laser's own channel. Physically the glare at the edge of the measured region cannot exceed what the capture measured
there times the gain (the capture would have measured it), so a ratio far above 1 there is the glare standing in
for the beam.

usage: PYTHONPATH=. python docs/bench/session65/halo_takeover.py CASE_DIR...
"""

import json
import sys
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import seeded_split, single_threaded
from lerobot_phantom.calibration.frame_models.laser_blinding import (
    GLARE_INNER_SCALE_REF_PX,
    halo_amplitude,
    laser_gain,
    laser_irradiance,
)
from lerobot_phantom.transforms import physics


def main() -> None:
    for folder in map(Path, sys.argv[1:]):
        seed = json.loads((folder / "out" / "report.json").read_text())["split"]["seed"]
        cfg = CalibrateConfig(
            attack="laser_blinding", measured=str(folder / "pairs"), out=str(folder / "unused"), seed=seed
        )
        problem = build_problem(cfg)
        fit_items, _ = seeded_split(problem.n_items, cfg.heldout, seed)
        effects = frozenset({"linear_light_saturation", "tone_shoulder", "halo_power_law"})
        with single_threaded():
            fit = problem.fit(effects, fit_items)
        p = {k: torch.tensor(v, dtype=torch.float64) for k, v in fit.params.items()}
        decode, _ = problem.tone_curve(effects, p)
        f = problem.probe_features
        with torch.no_grad():
            beam = laser_gain(p) * laser_irradiance(
                decode(f["beam"]), decode(f["dark"]), f["core_depth"], f["core_radius"], p
            )
            halo = physics.power_law_halo(
                f["radius"], halo_amplitude(p), p["halo_exponent"], GLARE_INNER_SCALE_REF_PX
            )
            glare = halo * f["colour"]
        channel = f["colour"][0].argmax()
        unmeasured = (f["unmeasured"][:, 0] > 0).numpy()
        radius = f["radius"][:, 0].numpy()
        ratio = (glare[:, channel] / beam[:, channel].clamp(min=1e-12)).numpy()
        edge = radius[unmeasured].min()
        line = []
        for low, high in ((edge, edge + 5), (edge + 5, edge + 15), (edge + 15, edge + 40), (edge + 40, 1e9)):
            inside = unmeasured & (radius >= low) & (radius < high)
            if inside.any():
                line.append(
                    f"{low - edge:.0f}-{min(high - edge, 999):.0f} px: {np.median(ratio[inside]):.3g}"
                )
        print(
            f"{folder.parts[-3].removeprefix('bt_')}: log10 gain {fit.params['log10_gain']:.2f}, halo level "
            f"{fit.params['halo_level']:.3f}, exponent {fit.params['halo_exponent']:.2f}; measured region's edge at "
            f"{edge:.1f} px; glare / (beam x gain) beyond it, median: " + ", ".join(line),
            flush=True,
        )


if __name__ == "__main__":
    main()
