"""Where the calibrated laser blinding attack, fed the camera's capture, parts from the calibration's frame model
(blinding_attack_from_calibration.py): on a camsim blinding draw calibrated by the CLI, each held-out frame predicted
by the attack's own physics (``physics.laser_injection`` with calibrated.json's options) with the capture read as
the frame model reads it, one step at a time:

0. the attack as a user runs it (``LaserBlinding(s, pattern=CAPTURE, **kwargs)``), with and without its random
   exposure draw (``exposure_spread``);
1. the attack's physics written out here without the exposure draw, reading the capture as the attack did at
   5ee0a3d: its encoded values all laser light, the glare centred on the frame in the transform's default colour
   (the glare per unit of the attack's power, as calibrated.json writes it since 39d1828);
2. 1 with the glare centred on the capture's spot (``pattern_centre``) in the capture's colour;
3. 2 with the capture's dark field taken out of its light (``dark_field``): the attack's reading since 39d1828;
4. 3 with the saturated core continued by the fitted beam width (``laser_irradiance``), as the frame model reads it.

RMSE in grey levels on the held-out pairs, beside the fit's. Usage: ``CAMSIM_SEED=0
PYTHONPATH=.:tests/calibration:tests python docs/bench/session88/blinding_attack_gap_probe.py CASE:CASE_SEED...``
"""

from __future__ import annotations

import sys

import torch
from calibrated_draws import calibrated_draws


def readings(problem, fit, tone, index: int) -> dict[str, tuple[torch.Tensor, torch.Tensor, torch.Tensor]]:
    """Steps 1-4 (the module docstring): the laser's light per unit power, the glare's centre (x, y) and colour."""
    from lerobot_phantom.calibration.frame_models.laser_blinding import laser_irradiance
    from lerobot_phantom.transforms import physics
    from lerobot_phantom.transforms.laser_blinding import LaserBlinding

    pair = problem.pairs[index]
    frame_centre = torch.tensor(
        [[round(0.5 * (pair.width - 1)), round(0.5 * (pair.height - 1))]], dtype=torch.float64
    )
    spot = torch.tensor([problem.centre(index)], dtype=torch.float64)
    decoded = physics.decode(pair.pattern.unsqueeze(0), tone)
    dark = physics.decode(problem.dark_fields[index].unsqueeze(0), tone)
    beam = physics.decode(problem.beams[index].profile.unsqueeze(0), tone)
    continued = (beam - dark).clamp(min=0.0)
    if "core_sigma_ref_px" in fit.params:
        core = (problem.core_depths[index], problem.core_radii[index].reshape(3, 1, 1))
        continued = laser_irradiance(beam[0], dark[0], *core, fit.params).unsqueeze(0)
    default_colour = torch.tensor(LaserBlinding(model="physical").color, dtype=torch.float64)
    colour = problem.colours[index]
    return {
        "1": (decoded, frame_centre, default_colour),
        "2": (decoded, spot, colour),
        "3": ((decoded - dark).clamp(min=0.0), spot, colour),
        "4": (continued, spot, colour),
    }


def injected(clean, physics_options, power: float, light, centre, colour) -> torch.Tensor:
    """The attack's physics (``physics.laser_injection``'s sum, written out) with this light and glare."""
    from lerobot_phantom.transforms import physics

    p = physics_options
    laser = power * light
    total = laser
    if p.glare_amplitude > 0:
        height, width = clean.shape[-2:]
        radius = physics.radial_distance(height, width, centre, dtype=torch.float64)
        scale = p.glare_scale_ref_px * max(height, width) / 256
        glare = physics.power_law_halo(radius, p.glare_amplitude, p.glare_exponent, scale)
        total = laser + power * glare * colour.reshape(1, 3, 1, 1)
    return physics.inject_linear_light(
        clean, total, auto_exposure=p.auto_exposure, metered_light=laser, gamma=p.tone
    )


def main() -> None:
    from lerobot_phantom.transforms.laser_blinding import LaserBlinding

    for draw in calibrated_draws("laser_blinding", sys.argv[1:]):
        problem, kwargs = draw.problem, draw.kwargs
        fit = draw.fit()
        p = LaserBlinding(model="physical", **{k: v for k, v in kwargs.items() if k != "model"}).physics
        squared: dict[str, list[torch.Tensor]] = {
            k: [] for k in ("fit", "attack", "attack, no exposure draw", "1", "2", "3", "4")
        }
        for i in draw.heldout:
            i = int(i)
            pair = problem.pairs[i]
            clean = pair.clean.unsqueeze(0)
            squared["fit"].append((problem.predict_pair(fit, i) - pair.attacked) ** 2)
            capture = str(draw.folder / "pairs" / f"pattern_{i:03d}.png")  # camsim.write_pairs' names
            user = LaserBlinding(pair.intensity, pattern=capture, seed=i, **kwargs)
            squared["attack"].append((user(clean.float())[0].double() - pair.attacked) ** 2)
            steady = LaserBlinding(pair.intensity, pattern=capture, **{**kwargs, "exposure_spread": 0.0})
            squared["attack, no exposure draw"].append(
                (steady(clean.float())[0].double() - pair.attacked) ** 2
            )
            for key, reading in readings(problem, fit, p.tone, i).items():
                predicted = injected(clean, p, pair.intensity * p.gain, *reading)
                squared[key].append((predicted[0] - pair.attacked) ** 2)

        def rmse(values):
            return 255 * float(torch.cat([v.ravel() for v in values]).mean().sqrt())

        print(
            f"{draw.name} case seed {draw.seed}, {len(draw.heldout)} held-out pairs, selected "
            f"{sorted(draw.report['extended']['effects'])}: fit {rmse(squared['fit']):.2f}; "
            + ", ".join(f"{k} {rmse(v):.2f}" for k, v in squared.items() if k != "fit"),
            flush=True,
        )


if __name__ == "__main__":
    main()
