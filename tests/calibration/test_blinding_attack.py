"""The laser blinding attack ``calibrated.json`` builds, against the frame model the calibration fitted: fed the
camera's own capture of the laser, the attack is the fitted model on the held-out frames, and its options are read
from the fit frames alone."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest
import torch

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames
from lerobot_phantom.transforms.laser_blinding import LaserBlinding


def heldout_rmse(predictions: list[torch.Tensor], targets: list[torch.Tensor]) -> float:
    errors = [(p.double() - t).ravel() for p, t in zip(predictions, targets, strict=True)]
    return float(torch.cat(errors).pow(2).mean().sqrt())


def test_the_attack_fed_the_cameras_capture_is_the_fitted_frame_model(tmp_path):
    """camsim's glare case (case seed 2074608951; calibrated, it selects linear light, its glare, the meter and a
    tone shoulder). The attack takes the pair's own capture as its pattern and reads it as the fit does
    (``capture.read_capture``: dark level out, noise smoothed, beam continued below the floor, core continued at
    the fitted width, glare added back where the capture measured it) and meters as the fit does, so on the
    held-out frames it is the fitted model but for the meter's pixels (all of them, where the fit reads a sample)
    and float32. Until session 89 it read the capture as stored with a divisor for the meter: 2.58 grey levels
    against the fit's 2.47; with the glare per unit intensity as the fit writes it, 23.04
    (docs/bench/session88/blinding_attack_*.txt)."""
    import test_independent_sim as sim

    problem, fit_items, heldout = sim.drawn_split("blinding_halo", 2074608951, tmp_path)
    effects = frozenset({"linear_light_saturation", "halo_power_law", "auto_exposure", "tone_shoulder"})
    fit = problem.fit(effects, fit_items)
    options = problem.transform_kwargs(fit)
    assert options["gain"] > 5 and options["core_sigma_ref_px"] == fit.params["core_sigma_ref_px"]
    targets = [problem.pairs[int(i)].attacked for i in heldout]
    fitted = [problem.predict_pair(fit, int(i)) for i in heldout]

    def attacked(i: int, **changes) -> torch.Tensor:
        pair = problem.pairs[i]
        attack = LaserBlinding(
            pair.intensity, pattern=str(tmp_path / f"pattern_{i:03d}.png"), **{**options, **changes}
        )
        return attack(pair.clean.unsqueeze(0).float())[0].double()

    attacks = [attacked(int(i)) for i in heldout]
    apart = torch.cat([(a - f).ravel() for a, f in zip(attacks, fitted, strict=True)])
    assert 255 * float(apart.pow(2).mean().sqrt()) < 0.25 and 255 * float(apart.abs().max()) < 3.0
    assert heldout_rmse(attacks, targets) < 1.02 * heldout_rmse(fitted, targets)
    per_intensity = {"glare_amplitude": options["glare_amplitude"] * options["gain"]}
    assert heldout_rmse([attacked(int(i), **per_intensity) for i in heldout], targets) > 3 * heldout_rmse(
        attacks, targets
    )


def test_the_attacks_options_are_read_from_the_fit_frames_alone(tmp_path):
    """camsim's auto-exposure case (case seed 1758681884: calibrated, it selects the meter and each frame's own
    exposure). The options calibrated.json holds (the meter's power, the glare's colour) must not change when the
    held-out frames and their captures do: until session 88 the meter's conversion to the transform's divisor read
    every pair's frames; the glare's colour is read from the fit frames' captures."""
    import test_independent_sim as sim

    problem, fit_items, heldout = sim.drawn_split("blinding_auto_exposure", 1758681884, tmp_path)
    effects = frozenset({"linear_light_saturation", "auto_exposure", "frame_exposure", "halo_power_law"})
    fit = problem.fit(effects, fit_items)
    options = problem.transform_kwargs(fit)
    assert options["meter_power"] == pytest.approx(fit.params["auto_exposure"]) and options["meter_power"] > 0
    # the glare's colour is the laser's: its brightest channel the captures' laser channel, at 1
    assert max(options["color"]) == 1.0 and options["color"].index(1.0) == problem.laser_channel
    pairs = list(problem.pairs)
    for i in heldout:
        pair = pairs[int(i)]
        recoloured = pair.pattern * torch.tensor([1.5, 0.5, 1.5], dtype=pair.pattern.dtype).reshape(3, 1, 1)
        pairs[int(i)] = dataclasses.replace(
            pair, pattern=recoloured.clamp(0, 1).flip(-1), attacked=pair.attacked.flip(-1)
        )
    altered = BlindingFrames(pairs, seed=problem.seed)
    assert altered.transform_kwargs(fit) == options
    every_frame = dataclasses.replace(fit, extra={**fit.extra, "items": np.arange(len(pairs))})
    read_from_every_frame = altered.transform_kwargs(every_frame)
    assert read_from_every_frame["color"] != pytest.approx(options["color"])
