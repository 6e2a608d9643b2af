"""Light projection frame pairs: the scene, the projected image and the captured frame, pixel by pixel."""

from __future__ import annotations

import torch

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import Pair, PixelProblem, flat_pixels
from lerobot_phantom.calibration.projection import ProjectionTerms, projection_predict, projection_warm


class ProjectionFrames(ProjectionTerms, PixelProblem):
    base_model = "alpha blend of the scene and the projected image (the paper's light projection)"
    # a filmic camera's shoulder and the surface's reflectance pay only together: without the reflectance term the
    # shoulder's fit runs its knee to a hard clip (exponent at its bound), and without the shoulder the reflectance
    # term's floor runs to its end (camsim master seed 458072150: additive light alone 3.87 grey levels, + shoulder
    # pinned, + shoulder + reflectance 3.01, cross-validated)
    joint_effects = 3

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        if any(p.pattern is None for p in pairs):
            raise ValueError(
                "light_projection frame pairs need a 'pattern' column: the image the attacker projected"
            )
        super().__init__(pairs, seed)

    def features(self, index: int, pixels: torch.Tensor | None) -> dict[str, torch.Tensor]:
        pair = self.pairs[index]
        surface = flat_pixels(pair.clean, pixels)
        return {
            "surface": surface,
            "projected": flat_pixels(pair.pattern, pixels),
            "strength": torch.full((len(surface), 1), pair.intensity, dtype=torch.float64),
        }

    def predict_features(self, effects, params, feats):
        return projection_predict(feats["surface"], feats["projected"], feats["strength"], effects, params)

    def warm(self, start: Fit | None, effects: frozenset[str]) -> dict[str, float] | None:
        return projection_warm(start, effects)
