"""The laser capture of one camsim blinding case read as a beam profile, against camsim's own irradiance, and the
linear-light fits with the laser's gain free and pinned at camsim's true power ratio.

Usage: ``CAMSIM_SEED=<master seed> PYTHONPATH=. python docs/bench/camsim_beam_colour.py PAIRS_DIR [CASE]`` from the
repository root (``PAIRS_DIR``: the case's ``pairs`` folder under a camsim run's basetemp; ``CASE``: default
``blinding_halo``). The case is rendered again from its seed, with camsim's laser spot and its power draws recorded,
so the script reads the truth the pairs were made from: per ring of distance from the spot, for each channel, the
light (linear, full wells) camsim put into the capture, what the capture holds above its dark level and what
``beam_profile`` reads; then the fit pairs' RMSE of ``linear_light_saturation`` (with and without the halo) at the
fitted gain and at the true one, ``intensity x peak power x core exposure / core fill`` per unit intensity.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, "tests/calibration")
sys.path.insert(1, "tests")  # tests/sampling.py, which the case selection imports

import camsim as cs
import test_independent_sim as sim
from camsim_blinding_nested_fits import fit_line

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import Param, seeded_split
from lerobot_phantom.calibration.frame_models import laser_blinding
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.transforms import physics

RINGS = [(0, 3), (3, 6), (6, 10), (10, 15), (15, 20), (20, 25), (25, 32), (32, 40), (40, 60)]


class RecordingGenerator:
    """A numpy generator that keeps the scalar uniform draws by their range (camsim draws the laser's peak power
    from (40, 120) and the capture's core fill from (0.5, 0.9))."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng, self.draws = rng, {}

    def __getattr__(self, name):
        return getattr(self.rng, name)

    def uniform(self, *args, **kwargs):
        value = self.rng.uniform(*args, **kwargs)
        if np.ndim(value) == 0:
            self.draws.setdefault(tuple(float(a) for a in args), float(value))
        return value


class PinnedGain(laser_blinding.BlindingFrames):
    """The blinding frame model with ``log10_gain`` held at ``pinned`` (None: free)."""

    pinned: float | None = None

    def param_specs(self, effects):
        specs = super().param_specs(effects)
        if self.pinned is None:
            return specs
        return [
            Param(p.name, self.pinned, self.pinned - 1e-3, self.pinned + 1e-3, scale=1e-3)
            if p.name == "log10_gain"
            else p
            for p in specs
        ]


def main() -> None:
    folder = Path(sys.argv[1])
    case = sim.CASE_BY_NAME[sys.argv[2] if len(sys.argv) > 2 else "blinding_halo"]
    seed, rng, camera = sim.case_camera(case)
    spots, exposures = [], []
    laser_spot, capture = cs.laser_spot, cs.capture

    def recording_spot(cam, centre, colour, *, core_px, halo):
        spots.append(laser_spot(cam, centre, colour, core_px=core_px, halo=halo))
        return spots[-1]

    def recording_capture(irradiance, cam, rng, exposure=None):
        exposures.append(exposure)
        return capture(irradiance, cam, rng, exposure=exposure)

    cs.laser_spot, cs.capture = recording_spot, recording_capture
    recorder = RecordingGenerator(rng)
    case.render(recorder, camera)
    cs.laser_spot, cs.capture = laser_spot, capture
    peak_power = recorder.draws[(40.0, 120.0)]
    exposure = exposures[
        0
    ]  # the session's first exposure: the capture's, and every frame's on a manual camera
    at_core = float(cs.optics(spots[0], camera).max()) * exposure
    fill = recorder.draws.get((0.5, 0.9))
    reference = peak_power if fill is None else fill / at_core
    truth = reference * cs.optics(spots[0], camera) * exposure  # the capture's laser light, full wells
    true_gain = peak_power / reference
    print(f"case {case.name} (case seed {seed}), {camera}")
    print(f"true gain {true_gain:.1f} per unit intensity (log10 {np.log10(true_gain):.3f})")

    pairs = load_pairs(folder, max_side=CalibrateConfig().max_side)
    pattern = pairs[0].pattern
    centre = laser_blinding.pattern_centre(pattern)
    dark = laser_blinding.dark_level(pattern, centre)
    dark_linear = physics.srgb_to_linear(dark).reshape(3, 1, 1)
    held = (physics.srgb_to_linear(pattern) - dark_linear).numpy()
    read = (
        physics.srgb_to_linear(laser_blinding.beam_profile(pattern, dark, centre).profile) - dark_linear
    ).numpy()
    ys, xs = np.mgrid[0 : pattern.shape[1], 0 : pattern.shape[2]]
    radius = np.hypot(xs - centre[0], ys - centre[1])  # working pixels: camsim frames are not resized
    print(
        "ring (px): per channel, camsim's light / the capture above its dark level / the read beam (full wells)"
    )
    for low, high in RINGS:
        ring = (radius >= low) & (radius < high)
        if ring.any():
            cells = "  ".join(
                f"c{c} {truth[..., c][ring].mean():.2e} / {held[c][ring].mean():.2e} / {read[c][ring].mean():.2e}"
                for c in range(3)
            )
            print(f"{low:2d}-{high:2d}  {cells}")

    config = CalibrateConfig()
    problem = PinnedGain(pairs, seed % 2**31)
    fit_items, heldout = seeded_split(problem.n_items, config.heldout, seed % 2**31)
    for pinned in (None, float(np.log10(true_gain))):
        problem.pinned = pinned
        for effects in (("linear_light_saturation",), ("linear_light_saturation", "halo_power_law")):
            fit = problem.fit(frozenset(effects), fit_items)
            print(
                f"gain {'free' if pinned is None else 'true'}: {fit_line(problem, fit, fit_items, heldout)}"
            )


if __name__ == "__main__":
    main()
