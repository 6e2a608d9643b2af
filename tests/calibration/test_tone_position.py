"""A light projection's gamma is named the camera's tone curve only if it holds at every position of the frame
(``ProjectionFrames.identification_checks``): frames of the independent simulator, at case seeds of draws whose
calibration named ``sensor_gamma`` (docs/bench/session60.md)."""

from __future__ import annotations

import pytest
import test_independent_sim as sim
import torch

from lerobot_phantom.calibration.frame_models.common import TONE_POSITION_EXCESS


def test_position_halves_split_each_pairs_sample_at_its_median_distance_from_the_centre(tmp_path):
    problem, items = sim.drawn_problem("projection_null", 7, tmp_path)
    inner, outer = problem.position_halves(items)
    for i, near, far in zip(items, inner, outer, strict=True):
        pair = problem.pairs[int(i)]
        assert torch.equal(torch.sort(torch.cat([near, far])).values, problem.samples[int(i)])
        assert len(near) >= len(far) > 0  # ties at the median join the inner half
        x_mid, y_mid = problem.centre(int(i))

        def radius(rows, pair=pair, x_mid=x_mid, y_mid=y_mid):
            return torch.hypot(
                (rows % pair.width - x_mid) / pair.width, (rows // pair.width - y_mid) / pair.height
            )

        assert radius(near).max() <= radius(far).min()


@pytest.mark.parametrize(
    ("name", "case_seed", "effects", "named"),
    [
        # master seed 4006062913 (session 56): the projector's falloff, no tone curve planted, named sensor_gamma
        ("projection_falloff_unnamed", 1900328395, {"sensor_gamma"}, False),
        # the same master seed's planted power-law tone curve (2.338), named with the light it bends
        (
            "projection_sensor_gamma",
            1225097670,
            {"additive_light", "albedo_modulation", "sensor_gamma"},
            True,
        ),
    ],
)
def test_a_gamma_is_the_cameras_only_if_both_position_halves_find_it(
    tmp_path, name, case_seed, effects, named
):
    problem, items = sim.drawn_problem(name, case_seed, tmp_path)
    fit = problem.fit(frozenset(effects), items)
    assert abs(fit.params["gamma"] - 1.0) > 0.1  # the pooled frame does show a gamma
    reasons = problem.identification_checks("sensor_gamma", fit, items)
    inner, outer = problem.gamma_by_position(fit, items)
    ratio = (fit.params["gamma"] - 1.0) / ((inner + outer) / 2 - 1.0)
    # the check's verdict is the stated rule on the figures it reports
    assert (reasons == []) == (0.0 < ratio <= TONE_POSITION_EXCESS)
    assert f"({inner:.3f})" in "".join(reasons) or named
    if named:
        assert reasons == []
    else:
        assert len(reasons) == 1 and "bends light that changes across the frame" in reasons[0], reasons
    # the check concerns the tone curve only
    assert problem.identification_checks("additive_light", fit, items) == []


def test_a_fit_on_given_pixels_is_the_fit_on_those_pixels_as_the_sample(tmp_path):
    problem, items = sim.drawn_problem("projection_null", 7, tmp_path)
    inner, _ = problem.position_halves(items)
    whole = problem.fit(frozenset(), items)
    on_inner = problem.fit_on_pixels(frozenset(), items, inner)
    assert on_inner.params != pytest.approx(whole.params)  # the pixels given were used
    for rows, i in zip(inner, items, strict=True):
        problem.samples[int(i)] = rows
    assert problem.fit(frozenset(), items).params == pytest.approx(on_inner.params)


@pytest.mark.parametrize(
    ("whole", "halves", "reason"),
    [
        (1.20, [0.98, 0.99], "does not depart from 1 on the side"),  # the halves bend the other way
        (1.20, [1.00, 1.00], "does not depart from 1 on the side"),  # the halves do not bend at all
        (1.30, [1.10, 1.10], "3.00 times as far, more than 1.5"),
        (0.80, [0.85, 0.87], None),  # 1.43 times as far, below 1: the rule holds on either side of 1
        (1.28, [1.20, 1.20], None),  # 1.4 times as far
    ],
)
def test_the_verdict_on_given_halves(tmp_path, monkeypatch, whole, halves, reason):
    problem, items = sim.drawn_problem("projection_null", 7, tmp_path)
    reasons = verdict_on_halves(problem, items, monkeypatch, whole, halves)
    if reason is None:
        assert reasons == []
    else:
        assert len(reasons) == 1 and reason in reasons[0], reasons


def verdict_on_halves(problem, items, monkeypatch, whole: float, halves: list[float]) -> list[str]:
    """The tone-position check's reasons for a gamma of ``whole`` on the frame whose halves gave ``halves``."""
    monkeypatch.setattr(problem, "gamma_by_position", lambda fit, items: halves)
    fit = problem.fit(frozenset({"sensor_gamma"}), items)
    fit.params["gamma"] = whole
    assert problem.identification_checks("additive_light", fit, items) == []  # the check is the tone curve's
    return problem.identification_checks("sensor_gamma", fit, items)


@pytest.mark.parametrize(
    ("whole", "halves", "reason"),
    [
        # session 82's flare-ghost draws 15 and 12 (docs/bench/session82/blinding_gamma_by_position_b4628c1.txt)
        (1.189, [1.172, 0.940], "times as far, more than 1.5"),
        (1.233, [1.175, 1.205], None),
    ],
)
def test_a_laser_blinding_gamma_holds_near_the_spot_and_away_from_it(
    tmp_path, monkeypatch, whole, halves, reason
):
    """The same verdict for laser blinding, its halves split at the laser spot (``BlindingFrames.centre``): a gamma
    fitted to light the library has no form for (a flare's ghost away from the spot) is not the camera's."""
    problem, items = sim.drawn_problem("blinding_null", 7, tmp_path)
    for near, far, i in zip(*problem.position_halves(items), items, strict=True):
        pair = problem.pairs[int(i)]
        x_spot, y_spot = problem.centre(int(i))

        def from_spot(rows, pair=pair, x_spot=x_spot, y_spot=y_spot):
            return torch.hypot(
                (rows % pair.width - x_spot) / pair.width, (rows // pair.width - y_spot) / pair.height
            )

        assert float(from_spot(near).max()) <= float(
            from_spot(far).min()
        )  # split at the spot, not the frame's centre
    reasons = verdict_on_halves(problem, items, monkeypatch, whole, halves)
    if reason is None:
        assert reasons == []
    else:
        assert len(reasons) == 1 and reason in reasons[0] and "nearest the laser spot" in reasons[0], reasons


def test_a_gamma_below_one_is_no_cameras(tmp_path):
    """Every camera's encoding compresses light, so a fitted decoding power stops at 1 (``tone.GAMMA_PARAM``), where
    selection sets it aside as a parameter at its bound: session 82's white balance draw (master seed 4157647104),
    which named ``sensor_gamma`` at 0.657 beside a blend, fits none below 1."""
    problem, items = sim.drawn_problem("projection_white_balance_unnamed", 3383599337, tmp_path)
    (spec,) = [p for p in problem.param_specs(frozenset({"sensor_gamma"})) if p.name == "gamma"]
    assert spec.low == 1.0
    fit = problem.fit(frozenset({"sensor_gamma"}), items)
    assert fit.params["gamma"] == pytest.approx(1.0, abs=1e-6)  # the fit runs to the bound
