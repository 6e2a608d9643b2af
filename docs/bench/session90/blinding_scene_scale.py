"""Where the blinding model puts the clean scene's light against the sensor's clip, beside camsim: the meter's
reaction to the laser depends on the scene's mean level under the clip (a scene metered to 0.18 of the full well
answers a clipped spot of a given area far more strongly than a scene read at 0.4). Per draw of camsim's
auto-exposure case, calibrated as a user calibrates it, and per pair: camsim's clean frame in the model's statistic
(the pixel's channel mean of the exposure times the irradiance at the sensor, clipped at the full well, averaged over
the frame) and the model's (its tone curve's decode of the stored clean frame, the same statistic over the meter's
probes), with the fitted meter power; then for each held-out pair the meter's factor ``k`` (attacked exposure over
the clean one's): camsim's own (its centre-weighted meter of clipped luma), the model's meter form (uniform, the
pixel's channel mean clipped) applied to camsim's true light in clean-frame units, and the model's uniform meter on
its own light at the exposure node that fits the frame best, alone and raised to the fitted power.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests:docs/bench/session88:docs/bench/session90 python
docs/bench/session90/blinding_scene_scale.py CASE:CASE_SEED...``
"""

from __future__ import annotations

import sys

import camsim
import numpy as np
import torch
from blinding_exposure_sensitivity import recorded_draws

from lerobot_phantom.calibration.frame_models.laser_blinding import METER_PROBES, exposure_nodes
from lerobot_phantom.transforms import physics


def meter_at_best_node(problem, fit, index: int) -> float:
    """The model's uniform meter factor ``k`` (power 1) for pair ``index`` at the exposure node that fits it best."""
    sse = problem.node_errors(fit, index)[1]
    factor = exposure_nodes(fit.params["exposure_spread"])[int(sse.argmin())]
    probes = problem.probe_slots([index])
    probes["exposure"] = torch.full_like(probes["exposure"], float(factor))
    decode, _ = problem.memoised_tone_curve(fit.effects, fit.params)
    with torch.no_grad():
        return float(
            problem.exposure_factor(fit.effects, {**fit.params, "auto_exposure": 1.0}, decode, probes)[0]
        )


def main() -> None:
    for draw, calls, clean_calls, attacked_calls in recorded_draws(sys.argv[1:]):
        problem, fit = draw.problem, draw.fit()
        truth = []
        for k in clean_calls:
            irradiance, cam, _, exposure = calls[k]
            truth.append(float(np.minimum(exposure * camsim.optics(irradiance, cam).mean(2), 1.0).mean()))
        decode, _ = problem.memoised_tone_curve(fit.effects, fit.params)
        with torch.no_grad():
            scene = problem.scene_light(fit.effects, fit.params, problem.probe_features, decode)
        model = scene.mean(1).clamp(max=1.0).reshape(-1, METER_PROBES).mean(1).numpy()
        print(
            f"{draw.name} case seed {draw.seed}: selected {sorted(fit.effects)}, meter power "
            f"{fit.params.get('auto_exposure', 0.0):.3f}; clean frames' mean clipped light, camsim "
            + " ".join(f"{v:.3f}" for v in truth)
            + "; the model's "
            + " ".join(f"{v:.3f}" for v in model)
            + f"; ratio model / camsim median {np.median(model / np.array(truth)):.2f}",
            flush=True,
        )
        for i in [int(i) for i in draw.heldout]:
            clean_irr, cam, _, clean_exposure = calls[clean_calls[i]]
            attacked_irr, _, _, attacked_exposure = calls[attacked_calls[i]]
            light = clean_exposure * camsim.optics(attacked_irr, cam).mean(2).reshape(1, -1)
            scene_light = clean_exposure * camsim.optics(clean_irr, cam).mean(2).reshape(1, -1)
            uniform_truth = float(
                physics.metered_exposure(torch.from_numpy(light), torch.from_numpy(scene_light))[0]
            )
            model_k = meter_at_best_node(problem, fit, i)
            print(
                f"  held-out {i}: the meter's factor k, camsim {attacked_exposure / clean_exposure:.3f}; the model's "
                f"uniform meter on camsim's light {uniform_truth:.3f}; the model's at its best node: uniform "
                f"{model_k:.3f}, raised to its power {model_k ** fit.params['auto_exposure']:.3f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
