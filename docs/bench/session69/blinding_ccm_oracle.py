"""What a colour correction matrix leaves of laser blinding frames when the model knows the camera exactly.

camsim's colour-correcting cameras (``CAMSIM_CCM=1``) add the laser's light and clip it in the raw channels, then mix
the channels with the matrix (its off-diagonals negative) and apply the tone curve. The library composes light in
the stored channels. This fits, on every pair of one drawn ``blinding_*`` case (the calibration's 800 sampled pixels
a pair), the library's blinding models with camsim's own tone curve in place of a fitted one, twice: as the library
composes (``stored``), and with the camera's true matrix (``raw``: the scene, the capture's beam and the glare's
colour taken to the raw channels by the matrix's inverse, the sum exposed and clipped there, then mixed by the
matrix). Prints each model's RMSE over all pixels of all pairs and its parameters.

Usage: ``CAMSIM_CCM=1 PYTHONPATH=.:tests/calibration python docs/bench/session69/blinding_ccm_oracle.py CASE SEED
PAIRS_DIR EFFECTS[,EFFECT...]...`` (PAIRS_DIR: the case's ``pairs`` folder as ``session64/run_camsim_case.py``
rendered it for that master seed).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws
from session67.projection_ccm_oracle import ACES_4, aces, filmic_decode

from lerobot_phantom.calibration.core import Param
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import (
    GLARE_INNER_SCALE_REF_PX,
    BlindingFrames,
    halo_amplitude,
    laser_gain,
    laser_irradiance,
)
from lerobot_phantom.transforms import physics


def filmic_encode(x: torch.Tensor) -> torch.Tensor:
    """camsim's filmic curve in torch (the fits differentiate through it; ``camsim.tone_curve`` is numpy)."""
    return physics.linear_to_srgb(aces(4 * x.clamp(0, 1)) / ACES_4)


def oracle_class(camera, composed_in: str, laser_colour=None):
    """BlindingFrames with camsim's exact tone curve and, for ``raw``, its true matrix; for ``raw_true_colour``, the
    laser's true raw colour too (the capture's stored laser channel read as the raw beam through it)."""
    if camera.tone == "filmic":
        curve = (filmic_decode, filmic_encode)
    elif camera.tone == "srgb":
        curve = (physics.srgb_to_linear, physics.linear_to_srgb)
    else:
        raise SystemExit(f"camera tone {camera.tone}: this oracle knows camsim's filmic and srgb curves")
    matrix = torch.tensor(np.reshape(camera.ccm, (3, 3)), dtype=torch.float64)
    inverse = torch.linalg.inv(matrix)

    class Exact(BlindingFrames):
        @classmethod
        def tone_curve(cls, effects, params):
            return curve

    class Raw(Exact):
        def compose(self, effects, params, f, decode):
            def to_raw(v):
                return decode(v) @ inverse.T

            colour = (f["colour"] @ inverse.T).clamp(min=0.0)
            colour = colour / colour.max(dim=1, keepdim=True).values.clamp(min=1e-9)
            return super().compose(effects, params, {**f, "colour": colour}, to_raw)

        def predict_features(self, effects, params, f, probes=None):
            decode, encode = self.tone_curve(effects, params)
            total = self.compose(effects, params, f, decode)
            if "auto_exposure" in effects:
                total = total * self.exposure_factor(effects, params, decode, probes)[f["pair"]].unsqueeze(1)
            return encode((total.clamp(0.0, 1.0) @ matrix.T).clamp(0.0, 1.0))

    identity = torch.eye(3, dtype=torch.float64)
    channel = int(np.argmax(laser_colour))
    faint = [c for c in range(3) if c != channel]

    class LaserChannel(Exact):
        """The beam read from the capture's laser channel alone, in the laser's colour (true or fitted), composed
        in the raw channels of ``mix`` (the true matrix, or the identity: the stored channels)."""

        mix = matrix
        fitted_colour = False

        def param_specs(self, effects):
            specs = super().param_specs(effects)
            if self.fitted_colour:
                # the laser's light in each faint channel over its own channel's; below 0 only in stored channels,
                # where a colour correction can take light away
                low = -1.0 if self.mix is identity else 0.0
                specs += [Param(f"colour_{c}", 0.1, low, 1.0, scale=0.1) for c in faint]
            if self.mix is None:
                specs += [
                    Param(f"ccm_{i}{j}", -0.1, -1.0, 0.0, scale=0.1)
                    for i in range(3)
                    for j in range(3)
                    if i != j
                ]
            return specs

        def matrix_used(self, params):
            if self.mix is not None:
                return self.mix
            # rows sum to 1 (white stays white), each off-diagonal from -1 to 0
            rows = []
            for i in range(3):
                off = [
                    torch.as_tensor(params[f"ccm_{i}{j}"], dtype=torch.float64) for j in range(3) if j != i
                ]
                row = off[:]
                row.insert(i, 1.0 - off[0] - off[1])
                rows.append(torch.stack(row))
            return torch.stack(rows)

        def colour(self, params):
            if not self.fitted_colour:
                return torch.as_tensor(laser_colour, dtype=torch.float64)
            parts = [torch.ones((), dtype=torch.float64)] * 3
            for c in faint:
                parts[c] = torch.as_tensor(params[f"colour_{c}"], dtype=torch.float64)
            return torch.stack(parts)

        def compose(self, effects, params, f, decode):
            colour = self.colour(params)
            mix = self.matrix_used(params)
            stored_share = (mix @ colour)[channel]
            one = slice(channel, channel + 1)
            beam = laser_irradiance(
                decode(f["beam"])[:, one],
                decode(f["dark"])[:, one],
                f["core_depth"][:, one],
                f["core_radius"][:, one],
                params,
            )
            s = f["strength"]
            light = s * f["exposure"] * laser_gain(params) * beam / stored_share * colour
            if "halo_power_law" in effects:
                unmeasured = f["unmeasured"] > 0
                glare_at = torch.where(unmeasured, f["radius"], f["dark_radius"])
                halo = physics.power_law_halo(
                    glare_at, halo_amplitude(params), params["halo_exponent"], GLARE_INNER_SCALE_REF_PX
                )
                glare = s * f["exposure"] * halo * colour / stored_share
                light = torch.where(unmeasured, torch.maximum(light, glare), light + glare)
            return decode(f["scene"]) @ torch.linalg.inv(mix).T + light

        def predict_features(self, effects, params, f, probes=None):
            decode, encode = self.tone_curve(effects, params)
            total = self.compose(effects, params, f, decode)
            if "auto_exposure" in effects:
                total = total * self.exposure_factor(effects, params, decode, probes)[f["pair"]].unsqueeze(1)
            return encode((total.clamp(0.0, 1.0) @ self.matrix_used(params).T).clamp(0.0, 1.0))

    def variant(mix, fitted):
        return type("Variant", (LaserChannel,), {"mix": mix, "fitted_colour": fitted})

    return {
        "stored": Exact,
        "raw": Raw,
        "raw_true_colour": variant(matrix, False),
        "raw_fitted_colour": variant(matrix, True),
        "stored_fitted_colour": variant(identity, True),
        "fitted_matrix_and_colour": variant(None, True),
    }[composed_in]


def drawn_colour(case: str, seed: int) -> np.ndarray:
    """The laser colour camsim drew for the case: the first draw of ``laser_blinding_pairs`` from the case's rng."""
    import camsim

    (*_, rng, _camera), *_ = case_draws(case, [seed])
    return camsim.LASER_COLOURS[rng.choice(list(camsim.LASER_COLOURS))]


def main() -> None:
    case, seed, folder, models = sys.argv[1], int(sys.argv[2]), Path(sys.argv[3]), sys.argv[4:]
    (*_, camera), *_ = case_draws(case, [seed])
    if camera.ccm is None:
        raise SystemExit("the drawn camera has no colour correction matrix: run with CAMSIM_CCM=1")
    print(
        f"{case} {seed}: camera tone {camera.tone}, colour correction "
        f"{np.reshape(camera.ccm, (3, 3)).round(3).tolist()}"
    )
    pairs = load_pairs(folder, max_side=256)
    items = np.arange(len(pairs))
    import camsim

    colours = [c for c in camsim.LASER_COLOURS.values() if np.allclose(c / c.max(), drawn_colour(case, seed))]
    for composed_in in (
        "stored",
        "raw",
        "raw_true_colour",
        "raw_fitted_colour",
        "stored_fitted_colour",
        "fitted_matrix_and_colour",
    ):
        problem = oracle_class(camera, composed_in, colours[0])(pairs, 0)
        fit = None
        for model in models:
            # each model starts where the one before it ended (as the selection warm-starts a model from its parent)
            fit = problem.fit(frozenset(model.split(",")), items, fit)
            sse, n = problem.squared_errors(fit, items)
            shown = {k: round(v, 3) for k, v in fit.params.items()}
            if "ccm_01" in fit.params:
                fitted = problem.matrix_used(fit.params).numpy()
                shown["matrix_error"] = round(float(np.abs(fitted - np.reshape(camera.ccm, (3, 3))).max()), 3)
            print(f"  {composed_in:20s} {model}: RMSE {np.sqrt(sse / n):.2f} grey levels, all pairs; {shown}")


if __name__ == "__main__":
    main()
