"""Laser colour strip frame model: the period scan and the tone curves the stripe's light adds under
(calibration/frame_models/laser_color_strip.py)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import Pair
from lerobot_phantom.calibration.frame_models.laser_color_strip import StripFrames
from lerobot_phantom.transforms.laser_color_strip import LaserColorStrip

HEIGHT, WIDTH = 48, 32
STRIPE = {"peak_r": 0.35, "peak_g": 0.08, "peak_b": 0.04, "on_share": 0.08, "exposure_share": 0.05}


def stripe_pairs(seed: int, period: float, n: int = 8) -> list[Pair]:
    """Frames lit by the model's own periodic stripes at a random pulse phase, plus read noise."""
    rng = np.random.default_rng(seed)
    params = {**STRIPE, "period_share": period}
    gains = torch.tensor([STRIPE[f"peak_{c}"] for c in "rgb"], dtype=torch.float64).reshape(3, 1, 1)
    pairs = []
    for i in range(n):
        clean = torch.from_numpy(rng.uniform(0.1, 0.6, (3, HEIGHT, WIDTH)))
        intensity = float(rng.uniform(0.6, 1.0))
        phase = rng.uniform(0, period * HEIGHT)
        light = StripFrames.row_light(params, HEIGHT, torch.tensor([phase], dtype=torch.float64))[0]
        attacked = clean + intensity * gains * light.reshape(1, -1, 1)
        noise = torch.from_numpy(rng.normal(0.0, 0.004, clean.shape))
        pairs.append(Pair(f"pair_{i}", clean, (attacked + noise).clamp(0.0, 1.0), None, intensity))
    return pairs


@pytest.mark.parametrize("period", [0.34, 0.47])
def test_the_period_scan_starts_in_the_planted_periods_valley(period):
    """The registered cost is many-valleyed in the period; the scan's best start must lie in the planted one, and
    the fit from it must recover the period."""
    problem = StripFrames(stripe_pairs(3, period), seed=0)
    items = np.arange(problem.n_items)
    starts = problem.period_starts(problem.initial_stripe(items, {}), items)
    assert starts[0]["period_share"] == pytest.approx(period, rel=0.06)
    fit = problem.fit(frozenset({"exposure_overlap", "stripe_period"}), items)
    assert fit.params["period_share"] == pytest.approx(period, rel=0.02)


def test_a_period_longer_than_the_frame_is_not_named_a_period():
    problem = StripFrames(stripe_pairs(3, 0.4), seed=0)
    items = np.arange(problem.n_items)
    effects = frozenset({"exposure_overlap", "stripe_period"})
    fit = problem.fit(effects, items)
    assert problem.identification_checks("stripe_period", fit, items) == []
    longer = Fit(effects, {**fit.params, "period_share": 1.4})
    (reason,) = problem.identification_checks("stripe_period", longer, items)
    assert "longer than the frame" in reason
    assert problem.identification_checks("exposure_overlap", longer, items) == []


@pytest.mark.parametrize("tone", [{}, {"gamma": 2.2}, {"shoulder": 30.0, "shoulder_exponent": 1.5}])
def test_the_stripes_tone_curves_invert(tone):
    encoded = torch.linspace(0.01, 1.0, 200, dtype=torch.float64)
    decode, encode = StripFrames.tone(tone)
    linear = decode(encoded)
    assert torch.allclose(encode(linear), encoded, atol=1e-9)
    # the light saturates at the sensor's full well: white stays white however much is added
    assert torch.allclose(encode(linear + 5.0), torch.ones_like(encoded))


def full_frame_prediction(
    problem: StripFrames, params: dict, index: int, phases: torch.Tensor
) -> torch.Tensor:
    """The stripe's prediction written out over every row of the frame (lit or not), one per phase: (P, 3, H, W)."""
    pair = problem.pairs[index]
    light = problem.row_light(params, pair.height, phases)
    gains = pair.intensity * problem.stripe_gains(params).reshape(1, 3, 1, 1)
    decode, encode = problem.tone(params)
    return encode(decode(pair.clean).unsqueeze(0) + gains * light[:, None, :, None])


@pytest.mark.parametrize(
    "tone",
    [
        {},
        {"gamma": 2.2},
        {"shoulder": 4.0, "shoulder_exponent": 1.5},
        {"shoulder": 4.0, "shoulder_exponent": 1.5, "gamma": 1.8},
    ],
    ids=["none", "gamma", "shoulder", "shoulder+gamma"],
)
def test_registered_costs_over_the_lit_rows_equal_the_whole_frame(tone):
    """Registered costs computed over the rows a pulse reaches (each other row costs its unlit error at every
    phase) equal the whole-frame formula at every phase, for one stripe or a periodic train and each tone curve,
    and the prediction at a phase is that phase's whole frame (the unlit frame a curve keeps, ``tone_memo``, must
    not be reused under the next curve)."""
    pairs = stripe_pairs(5, 0.47, n=3)
    for pair in pairs:
        # black pixels: the one level a tone curve's round trip does not return (clipped to its darkest light)
        pair.clean[:, ::7, ::5] = 0.0
    problem = StripFrames(pairs, seed=0)
    with torch.no_grad():
        for period in ({}, {"period_share": 0.47}):
            for curve in ({}, tone, {k: 1.3 * v for k, v in tone.items()}):
                params = {
                    k: torch.tensor(v, dtype=torch.float64) for k, v in {**STRIPE, **period, **curve}.items()
                }
                for index in range(len(pairs)):
                    phases, costs = problem.phase_costs(params, index)
                    whole = full_frame_prediction(problem, params, index, phases)
                    expected = ((whole - pairs[index].attacked) ** 2).sum(dim=(1, 2, 3)).numpy()
                    np.testing.assert_allclose(costs, expected, rtol=1e-12)
                    for k in (0, len(phases) // 2, len(phases) - 1):
                        predicted = problem.predict_stripe(params, index, float(phases[k]))
                        torch.testing.assert_close(predicted, whole[k], rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("period", [None, 0.47])
def test_the_pairs_stripes_predicted_together_are_each_pairs_own_to_the_bit(period):
    """The fit's residual takes every pair's row light from one call over the tallest frame's rows; frames of other
    heights must get exactly the rows a call for them alone gives."""
    rng = np.random.default_rng(5)
    pairs = []
    for i, height in enumerate([40, 47, 53, 61]):
        clean = torch.from_numpy(rng.uniform(0.1, 0.6, (3, height, WIDTH)))
        pairs.append(Pair(f"pair_{i}", clean, clean, None, float(rng.uniform(0.6, 1.0))))
    problem = StripFrames(pairs, seed=0)
    params = {k: torch.tensor(v, dtype=torch.float64) for k, v in STRIPE.items()}
    if period is not None:
        params["period_share"] = torch.tensor(period, dtype=torch.float64)
    items = np.array([3, 0, 2, 1])
    phases = {int(i): float(rng.uniform(-30.0, -5.0)) for i in items}  # stripes inside every frame
    together = problem.predict_stripes(params, items, phases)
    for predicted, i in zip(together, items, strict=True):
        assert torch.equal(predicted, problem.predict_stripe(params, int(i), phases[int(i)]))
    assert all(
        not torch.equal(predicted, pairs[int(i)].clean) for predicted, i in zip(together, items, strict=True)
    )


def test_the_phases_the_model_weighs_are_those_at_which_the_stripe_crosses_the_frame():
    """Without a period the model sees one pulse: row r integrates over [r + phase, r + phase + exposure] rows and
    the pulse is on over [0, on], so some row is lit exactly for phases in (-(h - 1) - exposure, on). Every phase the
    model weighs lights a row, and a row's step beyond either end lights none (until session 87 the span ran from
    -h to on + exposure: here 55 phases, 3 lighting nothing, and none for a stripe leaving the frame's bottom)."""
    problem = StripFrames(stripe_pairs(seed=2, period=0.47, n=1), seed=2)
    phases, _ = problem.phase_costs(STRIPE, 0)
    light = StripFrames.row_light(STRIPE, HEIGHT, phases)
    assert bool((light.amax(dim=1) > 0).all())
    beyond = torch.tensor([float(phases[0]) - 1.0, float(phases[-1]) + 1.0], dtype=torch.float64)
    assert float(StripFrames.row_light(STRIPE, HEIGHT, beyond).max()) == 0.0


@pytest.mark.parametrize("period", [None, 0.47])
def test_the_calibrated_attack_draws_the_models_stripe_at_every_phase_the_model_weighs(period):
    """calibrated.json's ``LaserColorStrip`` is the stripe model: at any pulse phase the model scores (without a
    period, a stripe crossing the frame anywhere, partly out of view at either edge), the attack adds what
    ``predict_stripe`` predicts, in the fitted shoulder's light. Its pulses come a frame and a stripe's length apart
    when no period was measured: one pulse a frame (until session 87) lit a second stripe at the frame's other edge
    where the first left it."""
    shoulder = {"shoulder": 30.0, "shoulder_exponent": 1.2}
    params = {**STRIPE, **shoulder, **({} if period is None else {"period_share": period})}
    effects = {"exposure_overlap", "tone_shoulder"} | ({"stripe_period"} if period else set())
    problem = StripFrames(stripe_pairs(seed=2, period=0.47, n=2), seed=2)
    fit = Fit(frozenset(effects), params)
    attack = LaserColorStrip(**problem.transform_kwargs(fit))
    pair = problem.pairs[0]
    phases, _ = problem.phase_costs(params, 0)
    for phase_rows in phases.tolist():
        drawn = attack.sample_params(1, HEIGHT, WIDTH, intensity=torch.tensor([pair.intensity]))
        drawn["phase_s"] = torch.tensor([phase_rows / HEIGHT], dtype=torch.float64)
        attacked = attack.apply_params(pair.clean.unsqueeze(0), drawn)[0]
        predicted = problem.predict_stripe(params, 0, phase_rows)
        assert float((attacked - predicted).abs().max()) < 1e-5, phase_rows
