"""Light projection on a camera whose ISP mixes its raw channels with a colour correction matrix (session 97): the
frame model composes the projected light in the raw channels (``projection_predict``), the attack does the same
(``physics.project_light``), and the matrix only shows where the light composes other than by adding."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from calibration_testkit import projection_pairs_with_spread_light

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.projection import (
    EFFECTS,
    SPREAD_HIGH_REF_PX,
    projection_kwargs,
    projection_nulls,
    projection_predict,
    projection_warm,
)
from lerobot_phantom.calibration.tone import correction_matrix
from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.light_projection import LightProjection

TAKES = {"ccm_red": 0.35, "ccm_green": 0.2, "ccm_blue": 0.25}
RAW_CROSSTALK = {f"crosstalk_{i}{j}": (0.8 if i == j else 0.15) for i in range(3) for j in range(3)}


def colours(n: int, seed: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    rng = np.random.default_rng(seed)
    surface, projected = (torch.from_numpy(rng.uniform(0, 1, (n, 3))) for _ in range(2))
    return surface, projected, torch.ones(n, 1, dtype=torch.float64)


def attack_light(options: dict, surface: torch.Tensor, projected: torch.Tensor) -> torch.Tensor:
    light = LightProjection(**options).project(
        surface.T.reshape(1, 3, -1, 1), projected.T.reshape(1, 3, -1, 1), torch.ones(1, dtype=torch.float64)
    )
    return light.reshape(3, -1).T


@pytest.mark.parametrize("emitted", [True, False])
def test_the_attack_composes_light_in_the_fitted_raw_channels_as_the_fit_does(emitted):
    """calibrated.json hands ``LightProjection`` the fitted matrix: its light reproduces the fit's prediction to
    rounding, with the reflectance, the clip, the cross-talk and a gamma, for a pattern the projector was sent and
    for one this camera captured (its stored light taken back to raw too, its channels at black among them); without
    the matrix it misses."""
    params = {"gamma": 2.2, "reflectance_floor": 0.02, "white": 0.8, **RAW_CROSSTALK, **TAKES}
    if emitted:
        params["projector_gamma"] = 2.0
    effects = frozenset(
        {
            "additive_light",
            "albedo_modulation",
            "channel_crosstalk",
            "clipping",
            "sensor_gamma",
            "colour_correction",
        }
    )
    surface, projected, strength = colours(400, seed=11)
    projected[::3, 1] = projected[1::3, 2] = 0.0  # channels a captured pattern stores at black
    predicted = projection_predict(surface, projected, strength, effects, params)
    kwargs = projection_kwargs(Fit(effects, params))
    assert np.allclose(np.reshape(kwargs["colour_correction"], (3, 3)), correction_matrix(params).numpy())
    assert torch.allclose(attack_light(kwargs, surface, projected), predicted, atol=1e-12)
    unmixed = {k: v for k, v in kwargs.items() if k != "colour_correction"}
    assert 255 * float((attack_light(unmixed, surface, projected) - predicted).abs().max()) > 20.0


def captured_through(correction: torch.Tensor, raw: torch.Tensor, gamma: float = 2.2) -> torch.Tensor:
    """``raw`` light (N, 3) as a board capture through ``correction`` stores it: mixed, clipped, 8-bit power law."""
    return torch.round((raw @ correction.T).clamp(0.0, 1.0) ** (1 / gamma) * 255) / 255


def test_a_captured_primary_stored_at_black_comes_back_as_its_own_raw_light_alone():
    """A board capture through the matrix stores a primary's fainter channels at 0 (the negative off-diagonals push
    them below it): read back, a primary's raw light is its own channels' alone, to the 8-bit file's rounding,
    where the whole matrix's inverse puts back into a red primary the green and blue the matrix took out. Colours
    with no channel at black read as the inverse reads them; rows and images read alike."""
    correction = correction_matrix(TAKES)
    primaries = torch.tensor(
        [[0.6, 0, 0], [0, 0.5, 0], [0, 0, 0.6], [0.5, 0.4, 0], [0, 0.3, 0.6], [0.5, 0, 0.5]],
        dtype=torch.float64,
    )
    pattern = captured_through(correction, primaries)
    assert bool((pattern <= physics.PATTERN_BLACK_LEVEL).any(1).all())
    light = pattern**2.2
    back = physics.captured_light_to_raw(light, pattern, correction, channel_dim=-1)
    assert torch.allclose(back, primaries, atol=0.01)
    inverse = light @ torch.linalg.inv(correction).T
    assert float((inverse - primaries).abs().max()) > 0.1
    assert float(inverse[0, 1:].min()) > 0.05  # the red primary's green and blue

    rng = np.random.default_rng(3)
    greys = torch.from_numpy(rng.uniform(0.3, 0.6, (50, 1)) + rng.uniform(0.0, 0.1, (50, 3)))
    pattern = captured_through(correction, greys)
    assert bool((pattern > physics.PATTERN_BLACK_LEVEL).all())
    light = pattern**2.2
    assert torch.allclose(
        physics.captured_light_to_raw(light, pattern, correction, channel_dim=-1),
        light @ torch.linalg.inv(correction).T,
        atol=1e-12,
    )

    mixed = torch.cat([primaries, greys])
    pattern = captured_through(correction, mixed)
    rows = physics.captured_light_to_raw(pattern**2.2, pattern, correction, channel_dim=-1)
    image = pattern.T.reshape(1, 3, 8, 7)
    assert torch.equal(physics.captured_light_to_raw(image**2.2, image, correction).reshape(3, -1).T, rows)


def test_a_captured_patterns_raw_light_differentiates_in_the_matrix():
    """The fit takes a torch Jacobian through the matrix's takes: the read-back's derivative matches a central
    difference, channels at black included."""
    raw = torch.tensor([[0.6, 0, 0], [0.5, 0.4, 0], [0.3, 0.35, 0.4]], dtype=torch.float64)
    pattern = captured_through(correction_matrix(TAKES), raw)
    takes = torch.tensor([TAKES[f"ccm_{c}"] for c in ("red", "green", "blue")], dtype=torch.float64)
    weights = torch.linspace(0.5, 1.5, 9, dtype=torch.float64).reshape(3, 3)

    def read(t: torch.Tensor) -> torch.Tensor:
        return (
            physics.captured_light_to_raw(pattern**2.2, pattern, physics.correction_matrix(t), channel_dim=-1)
            * weights
        ).sum()

    assert torch.autograd.gradcheck(read, (takes.clone().requires_grad_(True),))


def test_a_captured_pattern_is_taken_to_raw_before_it_spreads_in_the_fit_as_in_the_attack():
    """With ``light_spread`` the frame model spreads whole patterns (``ProjectionFrames.spread_light``): a captured
    pattern's light reaches the raw channels pixel by pixel first, as in the attack, whose frame it reproduces."""
    pairs = projection_pairs_with_spread_light(1.0, seed=2)
    problem = ProjectionFrames(pairs, seed=2, pattern_record="captured")
    effects = frozenset(
        {"additive_light", "albedo_modulation", "sensor_gamma", "light_spread", "colour_correction"}
    )
    # the widest spread: the fit's kernel radius (kept for it) is then the attack's
    params = {
        "strength": 0.4,
        "reflectance_floor": 0.05,
        "gamma": 2.2,
        "spread_ref_px": SPREAD_HIGH_REF_PX,
        **TAKES,
    }
    kwargs = projection_kwargs(Fit(effects, params))
    pair = pairs[0]
    fitted = problem.predict_features(effects, params, problem.features(0, None))
    attacked = LightProjection(**kwargs).project(
        pair.clean[None], pair.pattern[None], torch.tensor([pair.intensity], dtype=torch.float64)
    )
    assert torch.allclose(fitted, attacked[0].flatten(1).T, atol=1e-12)


def test_where_light_only_adds_the_matrix_is_a_change_of_basis_the_cross_talk_absorbs():
    """Without the reflectance's product or a clip, C (s_raw + M p) = s + (C M) p: the frames cannot tell the matrix
    from the cross-talk, which is why the term is said to show only through those two (its Effect text)."""
    effects = frozenset({"additive_light", "channel_crosstalk", "sensor_gamma"})
    params = {"gamma": 2.2, "projector_gamma": 2.2, **RAW_CROSSTALK}
    surface, projected, strength = colours(300, seed=5)
    surface = 0.2 + 0.3 * surface  # the sum stays inside the stored range, where nothing clips
    mixed = projection_predict(
        surface, projected, strength, effects | {"colour_correction"}, {**params, **TAKES}
    )
    raw = torch.tensor(
        [[RAW_CROSSTALK[f"crosstalk_{i}{j}"] for j in range(3)] for i in range(3)], dtype=torch.float64
    )
    stored = correction_matrix(TAKES) @ raw
    absorbed = {**params, **{f"crosstalk_{i}{j}": float(stored[i, j]) for i in range(3) for j in range(3)}}
    assert torch.allclose(
        mixed, projection_predict(surface, projected, strength, effects, absorbed), atol=1e-12
    )
    with_reflectance = effects | {"albedo_modulation", "colour_correction"}
    reflected = {**params, **TAKES, "reflectance_floor": 0.0}
    absorbed_reflected = {**absorbed, "reflectance_floor": 0.0}
    apart = projection_predict(
        surface, projected, strength, with_reflectance, reflected
    ) - projection_predict(
        surface, projected, strength, with_reflectance - {"colour_correction"}, absorbed_reflected
    )
    assert 255 * float(apart.abs().max()) > 5.0


def test_the_matrix_is_offered_to_frame_pairs_only_with_its_null_the_identity():
    assert "colour_correction" in {e.name for e in ProjectionFrames.candidates}
    assert "colour_correction" not in {e.name for e in EFFECTS}
    assert torch.equal(
        correction_matrix(projection_nulls("colour_correction")), torch.eye(3, dtype=torch.float64)
    )
    matrix = correction_matrix(TAKES)
    assert torch.allclose(matrix.sum(1), torch.ones(3, dtype=torch.float64))
    assert float(matrix[1, 0]) == -TAKES["ccm_red"] and float(matrix[0, 2]) == -TAKES["ccm_blue"]


def test_a_colour_correction_that_is_not_a_matrix_whose_rows_sum_to_one_is_refused():
    with pytest.raises(ValueError, match="rows sum to 1"):
        LightProjection(model="additive", colour_correction=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 2.0])
    with pytest.raises(ValueError, match="model='additive'"):
        LightProjection(
            model="blend", colour_correction=physics.correction_matrix(torch.zeros(3)).ravel().tolist()
        )


def test_the_matrix_is_offered_only_where_added_light_took_a_channel_down():
    """Light only adds: without a matrix no lit pixel loses light in a channel, and the term is not tried; where the
    pairs show such a fall (a matrix's negative off-diagonal taking a lit raw channel's light out of another) it is."""
    generator = torch.Generator().manual_seed(3)
    clean = torch.rand(3, 24, 32, generator=generator, dtype=torch.float64).mul(200).round().div(255)
    pattern = torch.zeros(3, 24, 32, dtype=torch.float64)
    pattern[0, 6:18, 8:24] = 1.0  # a red rectangle
    lit = pattern[0] > 0
    added = clean.clone()
    added[0][lit] = (added[0][lit] + 40 / 255).clamp(max=1.0)
    mixed = added.clone()
    mixed[1][lit] = (mixed[1][lit] - 20 / 255).clamp(
        min=0.0
    )  # green loses what red gained, as under a matrix

    def frames(attacked: torch.Tensor) -> ProjectionFrames:
        pairs = [
            Pair(f"pair{k}", clean, attacked, pattern, 1.0, {"pattern_record": "emitted"}, (32, 24))
            for k in range(4)
        ]
        return ProjectionFrames(pairs, seed=0)

    items = np.arange(4)
    reason = frames(added).unoffered(items)["colour_correction"]
    assert reason.startswith("0 of the 768 pixels")
    assert frames(mixed).unoffered(items) == {}


def test_a_negative_reflectance_floor_returns_no_light_below_zero_in_the_attack_as_in_the_fit():
    """A floor under 0 (the clean frame's veiling glare and black offset) leaves the darkest surfaces' reflectance
    below 0; the fit returns no light there (clamped at 0) and so must the attack, or it darkens them."""
    params = {"gamma": 2.2, "projector_gamma": 2.2, "strength": 2.0, "reflectance_floor": -0.05}
    effects = frozenset({"additive_light", "albedo_modulation", "sensor_gamma"})
    surface, projected, strength = colours(300, seed=7)
    surface = 0.3 * surface  # dark: many channels decode under 0.05 of white
    predicted = projection_predict(surface, projected, strength, effects, params)
    assert bool((surface**2.2 < 0.05).any())
    assert torch.allclose(
        attack_light(projection_kwargs(Fit(effects, params)), surface, projected), predicted, atol=1e-12
    )


def test_a_matrix_added_to_a_nested_fit_starts_where_the_model_is_that_fit():
    """``projection_warm`` starts a new colour correction at the identity: the warm start predicts what the nested
    fit predicts, so the search begins at its optimum (the default takes start elsewhere)."""
    nested = Fit(
        frozenset({"additive_light", "albedo_modulation", "channel_crosstalk", "clipping", "sensor_gamma"}),
        {"gamma": 2.2, "projector_gamma": 2.0, "reflectance_floor": 0.02, "white": 0.8, **RAW_CROSSTALK},
    )
    extended = nested.effects | {"colour_correction"}
    warm = projection_warm(nested, extended)
    assert all(warm[name] == 0.0 for name in TAKES)
    surface, projected, strength = colours(200, seed=9)
    assert torch.equal(
        projection_predict(surface, projected, strength, extended, warm),
        projection_predict(surface, projected, strength, nested.effects, nested.params),
    )
    defaults = {**warm, **{name: 0.1 for name in TAKES}}
    apart = projection_predict(surface, projected, strength, extended, defaults) - projection_predict(
        surface, projected, strength, nested.effects, nested.params
    )
    assert 255 * float(apart.abs().max()) > 1.0
