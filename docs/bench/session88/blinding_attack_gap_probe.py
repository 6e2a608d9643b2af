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

import json
import sys
import tempfile
from pathlib import Path

import torch


def main() -> None:
    import test_independent_sim as sim

    from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
    from lerobot_phantom.calibration.frame_models.laser_blinding import laser_irradiance
    from lerobot_phantom.transforms import physics
    from lerobot_phantom.transforms.laser_blinding import LaserBlinding

    torch.set_num_threads(1)
    for draw in sys.argv[1:]:
        name, seed = draw.split(":")
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            problem, fit_items, heldout = sim.drawn_split(name, int(seed), folder / "pairs")
            report = calibrate(
                CalibrateConfig(
                    attack="laser_blinding",
                    measured=str(folder / "pairs"),
                    out=str(folder / "out"),
                    seed=int(seed) % 2**31,
                )
            )
            kwargs = json.loads((folder / "out" / "calibrated.json").read_text())["kwargs"]
            effects = frozenset(report["extended"]["effects"])
            fit = problem.fit(effects, fit_items)
            p = LaserBlinding(model="physical", **{k: v for k, v in kwargs.items() if k != "model"}).physics
            squared: dict[str, list[torch.Tensor]] = {
                k: [] for k in ("fit", "attack", "attack, no exposure draw", "1", "2", "3", "4")
            }
            for i in heldout:
                i = int(i)
                pair = problem.pairs[i]
                clean = pair.clean.unsqueeze(0)
                squared["fit"].append((problem.predict_pair(fit, i) - pair.attacked) ** 2)
                capture_file = str(folder / "pairs" / f"pattern_{i:03d}.png")  # camsim.write_pairs' names
                user = LaserBlinding(pair.intensity, pattern=capture_file, seed=i, **kwargs)
                squared["attack"].append((user(clean.float())[0].double() - pair.attacked) ** 2)
                steady = LaserBlinding(
                    pair.intensity, pattern=capture_file, **{**kwargs, "exposure_spread": 0.0}
                )
                squared["attack, no exposure draw"].append(
                    (steady(clean.float())[0].double() - pair.attacked) ** 2
                )
                height, width = pair.height, pair.width
                power = pair.intensity * p.gain
                frame_centre = torch.tensor(
                    [[round(0.5 * (width - 1)), round(0.5 * (height - 1))]], dtype=torch.float64
                )
                spot = torch.tensor([problem.centre(i)], dtype=torch.float64)
                capture = pair.pattern.unsqueeze(0)
                decoded = physics.decode(capture, p.tone)
                dark = physics.decode(problem.dark_fields[i].unsqueeze(0), p.tone)
                beam = physics.decode(problem.beams[i].profile.unsqueeze(0), p.tone)
                params = {**fit.params}
                continued = (
                    laser_irradiance(
                        beam[0],
                        dark[0],
                        problem.core_depths[i],
                        problem.core_radii[i].reshape(3, 1, 1),
                        params,
                    ).unsqueeze(0)
                    if "core_sigma_ref_px" in params
                    else (beam - dark).clamp(min=0.0)
                )
                default_colour = torch.tensor(LaserBlinding(model="physical").color, dtype=torch.float64)
                colour = problem.colours[i]
                steps = {
                    "1": (decoded, frame_centre, default_colour, 1.0),
                    "2": (decoded, spot, colour, 1.0),
                    "3": ((decoded - dark).clamp(min=0.0), spot, colour, 1.0),
                    "4": (continued, spot, colour, 1.0),
                }
                for key, (light, centre, glare_colour, factor) in steps.items():
                    laser = power * factor * light
                    total = laser
                    if p.glare_amplitude > 0:
                        radius = physics.radial_distance(height, width, centre, dtype=torch.float64)
                        glare = physics.power_law_halo(
                            radius,
                            p.glare_amplitude,
                            p.glare_exponent,
                            p.glare_scale_ref_px * max(height, width) / 256,
                        )
                        total = laser + power * factor * glare * glare_colour.reshape(1, 3, 1, 1)
                    out = physics.inject_linear_light(
                        clean,
                        total,
                        auto_exposure=p.auto_exposure,
                        metered_light=laser,
                        gamma=p.tone,
                    )
                    squared[key].append((out[0] - pair.attacked) ** 2)

        def rmse(values):
            return 255 * float(torch.cat([v.ravel() for v in values]).mean().sqrt())

        print(
            f"{name} case seed {seed}, {len(heldout)} held-out pairs, selected {sorted(effects)}: fit "
            f"{rmse(squared['fit']):.2f}; "
            + ", ".join(f"{k} {rmse(v):.2f}" for k, v in squared.items() if k != "fit"),
            flush=True,
        )


if __name__ == "__main__":
    main()
