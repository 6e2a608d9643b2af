"""The physical laser blinding attack fed each held-out pair's own capture against the fitted frame model's
prediction, on camsim's glare case (case seed 2074608951, ``test_blinding_attack.py``'s draw): grey levels apart, RMS
and at most, with the capture's 8-bit values read exactly as the fit reads them (``patterns.exact_float64``, session
97) and with float32's values widened (before). Usage: ``CAMSIM_SEED=1 PYTHONPATH=.:tests/calibration:tests python
docs/bench/session97/blinding_parity.py``"""

from __future__ import annotations

import tempfile
from pathlib import Path

import test_independent_sim as sim
import torch

from lerobot_phantom.transforms import laser_blinding
from lerobot_phantom.transforms.laser_blinding import LaserBlinding


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        problem, fit_items, heldout = sim.drawn_split("blinding_halo", 2074608951, folder)
        effects = frozenset({"linear_light_saturation", "halo_power_law", "auto_exposure", "tone_shoulder"})
        fit = problem.fit(effects, fit_items)
        options = problem.transform_kwargs(fit)
        fitted = [problem.predict_pair(fit, int(i)) for i in heldout]
        exact = laser_blinding.exact_float64
        for label, widen in (("exact 8-bit values", exact), ("float32 widened", lambda t: t.double())):
            laser_blinding.exact_float64 = widen
            apart = []
            for i, prediction in zip(heldout, fitted, strict=True):
                pair = problem.pairs[int(i)]
                attack = LaserBlinding(
                    pair.intensity, pattern=str(folder / f"pattern_{int(i):03d}.png"), **options
                )
                apart.append(255 * (attack(pair.clean.unsqueeze(0).float())[0].double() - prediction).ravel())
            laser_blinding.exact_float64 = exact
            values = torch.cat(apart)
            print(
                f"{label}: {float(values.pow(2).mean().sqrt()):.3g} grey levels RMS, {float(values.abs().max()):.3g} at most"
            )


if __name__ == "__main__":
    main()
