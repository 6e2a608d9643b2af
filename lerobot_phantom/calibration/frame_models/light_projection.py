"""Light projection frame pairs: the scene, the projected image and the captured frame, pixel by pixel."""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial

import numpy as np
import torch

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import (
    Pair,
    ParameterMemo,
    PixelProblem,
    flat_pixels,
    parameter_values,
)
from lerobot_phantom.calibration.projection import (
    FRAME_EFFECTS,
    PATTERN_RECORD_COLUMN,
    SPREAD_HIGH_REF_PX,
    ProjectionTerms,
    check_pattern_record,
    projected_decode,
    projection_predict,
    projection_warm,
    tone_curve,
)
from lerobot_phantom.calibration.tone import CORRECTION_PARAMS, TONE_PARAMS
from lerobot_phantom.transforms.physics import gaussian_spread

# the parameters the projected light's decoding depends on, and its spreading
PROJECTED_PARAMS = (*TONE_PARAMS, "projector_gamma")
SPREAD_PARAMS = (*PROJECTED_PARAMS, "spread_ref_px")
# a captured pattern reaches the raw channels through the fitted matrix (projected_decode); an emitted one is raw
# light already, and a step of the matrix must not decode and spread it again
CORRECTION_NAMES = tuple(p.name for p in CORRECTION_PARAMS)
# a finite-difference Jacobian moves one parameter at a time, so every column but the light's own repeats the
# decoded and spread light of the point it is taken at (decoding and spreading took 75 of a 101 s calibration,
# hidden-effects projection case, docs/bench/session37.md): kept for the point and a step of each light parameter,
# the surface's and the projected light each
LIGHT_MEMO_SIZE = 2 * (1 + len(SPREAD_PARAMS) + len(CORRECTION_NAMES))


def projected_light_params(params: dict, spread: bool) -> tuple[str, ...]:
    """The parameters the projected light of a model with ``params`` depends on (``light_spread`` when ``spread``)."""
    names = SPREAD_PARAMS if spread else PROJECTED_PARAMS
    return names if "projector_gamma" in params else (*names, *CORRECTION_NAMES)


# colour_correction's sign in the pairs: light only adds, so where no matrix mixes the raw channels no channel of a
# pixel the pattern lights falls from the clean frame to the attacked one beyond noise and compression; a matrix's
# negative off-diagonals take a strongly lit raw channel's light out of the others. On camsim's additive-light cases
# the share of lit pixels with a channel 16 grey levels lower is at most 0.0004 on 26 draws without a matrix and at
# least 0.0164 on 8 with one (docs/bench/session97/ccm_signature.txt); offered on every draw, the matrix named nothing
# without one and took 1.6-1.9x the CPU
LIT_PATTERN = 0.5
FALLEN_GREY_LEVELS = 16
MIN_FALLEN_SHARE = 0.005


def lit_and_fallen(pair: Pair) -> tuple[int, int]:
    """(pixels the pair's pattern lights, those with a channel stored ``FALLEN_GREY_LEVELS`` or more lower in the
    attacked frame than in the clean one)."""
    lit = pair.pattern.amax(0) >= LIT_PATTERN
    fallen = 255.0 * (pair.clean - pair.attacked).amax(0) >= FALLEN_GREY_LEVELS - 0.5
    return int(lit.sum()), int((lit & fallen).sum())


class ProjectionFrames(ProjectionTerms, PixelProblem):
    base_model = "alpha blend of the scene and the projected image (the paper's light projection)"
    candidates = FRAME_EFFECTS
    # a filmic camera's shoulder and the surface's reflectance pay only together: without the reflectance term the
    # shoulder's fit runs its knee to a hard clip (exponent at its bound), and without the shoulder the reflectance
    # term's floor runs to its end (camsim master seed 458072150: additive light alone 3.87 grey levels, + shoulder
    # pinned, + shoulder + reflectance 3.01, cross-validated)
    joint_effects = 3

    def __init__(self, pairs: list[Pair], seed: int, pattern_record: str | None = None) -> None:
        """``pattern_record``: what the pairs' patterns are (``PATTERN_RECORDS``); None reads it from the pairs'
        ``pattern_record`` column, one value for all."""
        if any(p.pattern is None for p in pairs):
            raise ValueError(
                "light_projection frame pairs need a 'pattern' column: the image the attacker projected"
            )
        recorded = {p.settings.get(PATTERN_RECORD_COLUMN) for p in pairs}
        if pattern_record is None:
            if len(recorded) != 1 or None in recorded:
                raise ValueError(
                    f"light_projection frame pairs must say what their patterns are: a {PATTERN_RECORD_COLUMN} "
                    f"column in pairs.csv with one value for all pairs (found {sorted(map(str, recorded))}) or "
                    "--pattern-record; valid: emitted (the frame the projector was sent) or captured (the "
                    "projection as this camera captured it, e.g. on a board in the dark)"
                )
            (pattern_record,) = recorded
            self.pattern_record_source = f"pairs.csv column {PATTERN_RECORD_COLUMN}"
        elif recorded - {None, pattern_record}:
            raise ValueError(
                f"--pattern-record {pattern_record} contradicts the pairs' {PATTERN_RECORD_COLUMN} column "
                f"({sorted(map(str, recorded - {None}))}); drop the flag"
            )
        else:
            self.pattern_record_source = "--pattern-record"
        self.pattern_record = check_pattern_record(pattern_record, self.pattern_record_source)
        super().__init__(pairs, seed)
        # one kernel for every value a fit tries: as wide as the widest spread at the smallest working scale
        self.spread_radius = max(math.ceil(3.0 * SPREAD_HIGH_REF_PX / p.to_reference) for p in pairs)
        self.light_memo = ParameterMemo(LIGHT_MEMO_SIZE)

    def memoised_light(
        self, kind: str, feats: dict, effects, params: dict, names: tuple, compute: Callable[[], torch.Tensor]
    ) -> torch.Tensor:
        """``compute()``, reused while the pixels (``feats``), the effects and the parameters ``names`` repeat."""
        return self.light_memo.get(
            feats["pixel"], lambda: (kind, frozenset(effects), parameter_values(params, names)), compute
        )

    def features(self, index: int, pixels: torch.Tensor | None) -> dict[str, torch.Tensor]:
        pair = self.pairs[index]
        surface = flat_pixels(pair.clean, pixels)
        return {
            "surface": surface,
            "projected": flat_pixels(pair.pattern, pixels),
            "strength": torch.full((len(surface), 1), pair.intensity, dtype=torch.float64),
            # light_spread needs each pixel's neighbours: the pair's whole pattern, and which pixels the rows are
            "pair": torch.tensor([index]),
            "pixel": torch.arange(pair.height * pair.width)
            if pixels is None
            else torch.as_tensor(pixels).long(),
            "pixel_count": torch.tensor([len(surface)]),
        }

    def spread_light(self, effects, params, feats) -> torch.Tensor:
        """Each row's projected light (``projected_decode``), spread over its neighbours (``light_spread``)."""
        decode = projected_decode(effects, params, channel_dim=-3)
        pairs = feats["pair"].tolist()
        rows = torch.split(feats["pixel"], feats["pixel_count"].tolist())
        light = [None] * len(pairs)
        # pairs of one size spread together (one convolution), pairs resized to other sizes apart
        for shape in {self.pairs[i].pattern.shape for i in pairs}:
            members = [k for k, i in enumerate(pairs) if self.pairs[i].pattern.shape == shape]
            patterns = torch.stack([self.pairs[pairs[k]].pattern for k in members])
            scales = torch.tensor([self.pairs[pairs[k]].to_reference for k in members], dtype=torch.float64)
            sigma = params["spread_ref_px"] / scales
            spread = gaussian_spread(decode(patterns), sigma, radius=self.spread_radius).flatten(2)
            for j, k in enumerate(members):
                light[k] = spread[j][:, rows[k]].T
        return torch.cat(light)

    def predict_features(self, effects, params, feats):
        decode, _ = tone_curve(effects, params)
        spread = "light_spread" in effects
        projected = (
            partial(self.spread_light, effects, params, feats)
            if spread
            else partial(projected_decode(effects, params), feats["projected"])
        )
        return projection_predict(
            feats["surface"],
            feats["projected"],
            feats["strength"],
            effects,
            params,
            surface_light=self.memoised_light(
                "surface", feats, effects, params, TONE_PARAMS, partial(decode, feats["surface"])
            ),
            projected_light=self.memoised_light(
                "projected", feats, effects, params, projected_light_params(params, spread), projected
            ),
        )

    def warm(self, start: Fit | None, effects: frozenset[str]) -> dict[str, float] | None:
        return projection_warm(start, effects)

    def clean_colours(self, items: np.ndarray) -> torch.Tensor:
        return torch.cat([self.pairs[int(i)].clean.flatten(1).T for i in items])

    def unoffered(self, fit_items: np.ndarray) -> dict[str, str]:
        """``colour_correction`` where no lit pixel of the fit pairs lost light in a channel (``lit_and_fallen``)."""
        pairs = np.unique(fit_items)
        lit, fallen = (sum(c) for c in zip(*(lit_and_fallen(self.pairs[i]) for i in pairs), strict=True))
        if lit and fallen >= MIN_FALLEN_SHARE * lit:
            return {}
        return {
            "colour_correction": f"{fallen} of the {lit} pixels the patterns of the {len(pairs)} fit pairs light "
            f"store a channel {FALLEN_GREY_LEVELS} or more grey levels lower than the clean frame, a share under "
            f"{MIN_FALLEN_SHARE:g}: the projected light only added, no matrix took it out of another channel"
        }

    def identification_checks(self, effect: str, fit: Fit, items: np.ndarray) -> list[str]:
        """A gamma is named the camera's tone curve only if it holds at every position (``tone_position_checks``):
        one that only the pooled frame shows stands for light that changes across the frame (a projector's
        falloff). A clip must lie above the clean frames (``ProjectionTerms.identification_checks``)."""
        if effect == "sensor_gamma":
            return self.tone_position_checks(fit, items)
        return super().identification_checks(effect, fit, items)
