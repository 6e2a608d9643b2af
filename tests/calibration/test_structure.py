"""``calibration/structure.py``: structure left in a residual is reported with what and where; noise is not."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
import torch
from calibration_testkit import projection_pairs_with_spread_light
from scipy import ndimage

from lerobot_phantom.calibration.core import Fit, bin_index, binned_rmse
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.structure import (
    FAMILY_ALPHA,
    MIN_TESTED_ITEMS,
    NeighbourPairs,
    ResidualSample,
    binned_columns,
    correlation_of_totals,
    displacement_columns,
    explained_share_of_totals,
    line_terms,
    moment_columns,
    neighbour_tests,
    residual_structure,
    structure_summary,
)


class FakeProblem:
    """Residual maps per item: noise, plus an optional ramp along the rows."""

    def __init__(self, ramp: float, smooth: bool = False, items: int = 6, seed: int = 0) -> None:
        rng = np.random.default_rng(seed)
        self.maps = []
        for _ in range(items):
            noise = rng.normal(0.0, 1.0, (40, 50))
            if smooth:  # a residual image, not noise: a running mean over 9 columns
                noise = np.apply_along_axis(lambda r: np.convolve(r, np.ones(9) / 3.0, "same"), 1, noise)
            rows = np.linspace(0.0, 1.0, 40)[:, None] * np.ones((1, 50))
            self.maps.append(noise + ramp * (rows - 0.5))

    def residual_sample(self, fit, items, rng):
        sample = ResidualSample([], {"row": [], "column": []}, {"neighbours_along_rows": NeighbourPairs()})
        for i in items:
            residual = self.maps[int(i)]
            ys, xs = np.mgrid[0:40, 0:50] / np.array([39.0, 49.0])[:, None, None]
            sample.residual.append(residual.ravel())
            sample.covariates["row"].append(ys.ravel())
            sample.covariates["column"].append(xs.ravel())
            sample.neighbours["neighbours_along_rows"].pairs.append(
                (residual[:, :-3].ravel(), residual[:, 3:].ravel())
            )
        return sample


def run(problem, base_mse=1.0):
    return residual_structure(
        problem, None, np.arange(len(problem.maps)), base_mse=base_mse, rng=np.random.default_rng(0)
    )


def eta_squared(residual: np.ndarray, bins: np.ndarray) -> float:
    """The textbook form: the squared bin means, weighted by bin size, over the residual's sum of squares."""
    means = [residual[bins == b].mean() for b in np.unique(bins)]
    sizes = [np.sum(bins == b) for b in np.unique(bins)]
    return float(np.dot(sizes, np.square(means)) / np.sum(residual**2))


def pearson(a: np.ndarray, b: np.ndarray) -> float:
    return 0.0 if np.std(a) == 0 or np.std(b) == 0 else float(np.corrcoef(a, b)[0, 1])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_resummed_statistics_are_those_of_the_resampled_values(seed):
    # items of unequal size; a resample repeats some and drops others; one item is constant (a correlation of 0)
    rng = np.random.default_rng(seed)
    residual = [rng.normal(0.3, 1.0, size) for size in (5, 17, 2, 30, 9)]
    covariate = [rng.uniform(0.0, 4.0, len(r)) + 0.2 * r for r in residual]
    bins = [np.minimum((c * 2).astype(int), 7) for c in covariate]
    columns = np.array(
        [
            np.concatenate([binned_columns(r, b, 8), moment_columns(c, r)])
            for r, b, c in zip(residual, bins, covariate, strict=True)
        ]
    )
    for chosen in (
        np.arange(5),
        np.array([0, 0, 3, 4, 4]),
        np.array([2, 2, 2, 2, 1]),
        np.array([2, 2, 2, 2, 2]),
    ):
        totals = columns[chosen].sum(axis=0, keepdims=True)
        residual_chosen = np.concatenate([residual[i] for i in chosen])
        covariate_chosen = np.concatenate([covariate[i] for i in chosen])
        bins_chosen = np.concatenate([bins[i] for i in chosen])
        assert explained_share_of_totals(totals[:, :17], 8)[0] == pytest.approx(
            eta_squared(residual_chosen, bins_chosen), rel=1e-9, abs=1e-12
        )
        assert correlation_of_totals(totals[:, 17:])[0] == pytest.approx(
            pearson(covariate_chosen, residual_chosen), rel=1e-9, abs=1e-12
        )
    constant = np.array([moment_columns(np.full(6, 2.5), rng.normal(size=6))])
    assert correlation_of_totals(constant)[0] == 0.0


def test_noise_leaves_no_structure():
    result = run(FakeProblem(ramp=0.0))
    assert not result["structure_remains"], result["summary"]
    assert {t["variable"] for t in result["tests"]} == {"row", "column", "neighbours_along_rows"}


def test_a_row_ramp_is_reported_with_its_variable_and_place():
    result = run(FakeProblem(ramp=3.0))
    assert result["structure_remains"]
    flagged = {t["variable"] for t in result["tests"] if t["significant"]}
    assert "row" in flagged and "column" not in flagged  # a row ramp also makes neighbours in a row alike
    assert "depends on row" in result["summary"] and "r = +" in result["summary"]


def test_the_reported_estimates_are_the_statistics_of_every_item():
    problem = FakeProblem(ramp=1.0, smooth=True)
    tests = {t["variable"]: t for t in run(problem)["tests"]}
    residual = np.concatenate([m.ravel() for m in problem.maps])
    rows = np.concatenate([(np.mgrid[0:40, 0:50][0] / 39.0).ravel()] * len(problem.maps))
    assert tests["row"]["value"] == pytest.approx(eta_squared(residual, bin_index(rows, 8)[0]), rel=1e-9)
    assert tests["row"]["r"]["estimate"] == pytest.approx(pearson(rows, residual), rel=1e-9)
    left = np.concatenate([m[:, :-3].ravel() for m in problem.maps])
    right = np.concatenate([m[:, 3:].ravel() for m in problem.maps])
    assert tests["neighbours_along_rows"]["value"] == pytest.approx(pearson(left, right), rel=1e-9)


def test_smooth_residual_is_reported_as_neighbour_correlation():
    result = run(FakeProblem(ramp=0.0, smooth=True))
    assert [t["variable"] for t in result["tests"] if t["significant"]] == ["neighbours_along_rows"]
    test = next(t for t in result["tests"] if t["variable"] == "neighbours_along_rows")
    assert test["statistic"] == "lag-3 correlation" and "residual is smooth" in result["summary"]


def test_neighbours_paired_otherwise_say_how_and_where_they_agree_most_and_keep_it_when_joined():
    """A table's rows are paired by their inputs, not along a line: the finding says how, and in which group of
    pairs (a table's projected colour) the two residuals share the most."""
    pairing = "the residuals of each row and of the row nearest to it in its inputs"

    def sample(pairs, group):
        return ResidualSample(
            [np.zeros(1)] * len(pairs),
            {},
            {"nearest_inputs": NeighbourPairs(pairs, pairing, [group] * len(pairs))},
        )

    rng = np.random.default_rng(3)
    shared = rng.normal(size=(400, 3))
    pairs = [(row, row + rng.normal(scale=0.3, size=3)) for row in shared]
    # the second group's residuals are twice the first's: they share four times the mean product
    joined = sample(pairs[:200], "dim").joined(sample([(2 * a, 2 * b) for a, b in pairs[200:]], "bright"))
    assert joined.neighbours["nearest_inputs"].pairing == pairing
    assert joined.neighbours["nearest_inputs"].groups == ["dim"] * 200 + ["bright"] * 200
    (test,) = neighbour_tests(joined, lambda statistic: 1.0, rng)
    assert test["statistic"] == "neighbour correlation" and test["pairing"] == pairing
    assert test["significant"] and test["value"] == pytest.approx(1 / np.sqrt(1 + 0.3**2), abs=0.03)
    bright = np.mean([np.sum(4 * a * b) / 3 for a, b in pairs[200:]])
    assert test["where"].endswith(f"most under bright: {np.sqrt(bright):.3g}"), test["where"]
    summary = structure_summary([test])
    assert summary.startswith(f"unexplained structure: neighbours err alike: {pairing} correlate ")
    (unrelated,) = neighbour_tests(
        sample([(row, rng.normal(size=3)) for row in shared], "any"), lambda s: 1.0, rng
    )
    assert not unrelated["significant"] and abs(unrelated["value"]) < 0.1


def test_pairs_that_share_rows_are_resampled_as_one_cluster():
    """Stars of rows nearest to one centre: each leaf's pair holds the centre's residual, so 200 pairs are 20
    clusters' worth of evidence; the interval that resamples clusters is wider (1.32x here), the estimate the same."""
    rng = np.random.default_rng(8)
    pairs, clusters = [], []
    for star in range(20):
        centre = rng.normal(size=3)
        for _ in range(10):
            pairs.append((centre + rng.normal(scale=1.5, size=3), centre))
            clusters.append(star)
    independent = NeighbourPairs(pairs, "leaf and centre")
    clustered = NeighbourPairs(pairs, "leaf and centre", clusters=clusters)
    widths, values = [], []
    for neighbours in (independent, clustered):
        sample = ResidualSample([np.zeros(3)] * len(pairs), {}, {"stars": neighbours})
        (test,) = neighbour_tests(sample, lambda statistic: 1.0, np.random.default_rng(0))
        widths.append(test["interval"]["high"] - test["interval"]["low"])
        values.append(test["value"])
    assert values[0] == values[1]
    assert widths[1] > 1.2 * widths[0], widths
    columns = np.array([moment_columns(a, b) for a, b in pairs])
    assert np.allclose(clustered.resampled_columns(columns).sum(0), columns.sum(0))
    joined = clustered.joined(clustered)
    assert joined.clusters == clusters + [20 + c for c in clusters]


class RefitProblem(FakeProblem):
    """Per-item ramps (``ramps[i]``); fits remember the items they were fitted on, and every residual asked for
    is checked against them."""

    def __init__(self, ramps: list[float]) -> None:
        super().__init__(ramp=0.0, items=len(ramps))
        rows = np.linspace(0.0, 1.0, 40)[:, None] * np.ones((1, 50))
        self.maps = [m + r * (rows - 0.5) for m, r in zip(self.maps, ramps, strict=True)]
        self.fitted_on: list[set[int]] = []
        self.predicted: list[int] = []

    def fit(self, effects, items, start=None):
        assert start is None, "a cross-fitted refit must not start from the fit that saw every item"
        self.fitted_on.append({int(i) for i in items})
        return Fit(effects, {}, {"fitted_on": self.fitted_on[-1]})

    def residual_sample(self, fit, items, rng):
        seen = fit.extra.get("fitted_on", set()) & {int(i) for i in items}
        assert not seen, f"items {sorted(seen)} predicted by a fit that saw them"
        self.predicted += [int(i) for i in items]
        return super().residual_sample(fit, items, rng)

    def item_squared_errors(
        self, fit, items
    ):  # the outlying-item test's reference (the written fit's own items)
        return np.array([np.sum(self.maps[int(i)] ** 2) for i in items]), np.full(len(items), 2000.0)


def structure_of(problem, heldout, folds):
    fit_items = np.setdiff1d(np.arange(len(problem.maps)), heldout)
    return residual_structure(
        problem,
        Fit(frozenset({"effect"}), {}, {"fitted_on": set(fit_items.tolist())}),
        np.asarray(heldout),
        base_mse=1.0,
        rng=np.random.default_rng(0),
        fit_items=fit_items,
        folds=folds,
        seed=3,
    )


def test_few_heldout_items_are_joined_by_the_fit_items_cross_fitted_residuals():
    # two held-out items, one of them flat: over two items the bootstrap's 5% end is the flat item's own value
    ramps = [0.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0]
    alone = structure_of(RefitProblem(ramps), heldout=[0, 1], folds=None)
    assert not alone["structure_remains"], alone["summary"]
    problem = RefitProblem(ramps)
    joined = structure_of(problem, heldout=[0, 1], folds=4)
    assert joined["structure_remains"] and "depends on row" in joined["summary"], joined["summary"]
    assert "6 fit items" in joined["tested_on"] and "4 folds" in joined["tested_on"]
    # every fit item predicted once, by one of four refits that left it out (residual_sample checks that)
    assert sorted(problem.predicted) == list(range(8)) and len(problem.fitted_on) == 4
    assert all(len(trained) >= 4 for trained in problem.fitted_on)


def test_enough_heldout_items_are_tested_alone():
    problem = RefitProblem([3.0] * 12)
    heldout = list(range(MIN_TESTED_ITEMS))
    result = structure_of(problem, heldout=heldout, folds=4)
    assert problem.fitted_on == [] and sorted(problem.predicted) == heldout
    assert result["tested_on"] == "held-out residual of the written model (base + identified effects)"


def test_structure_too_small_against_the_base_error_is_not_reported():
    assert not run(FakeProblem(ramp=3.0), base_mse=1e4)["structure_remains"]


def test_problems_without_a_residual_sample_are_not_tested():
    class Table:
        def residual_sample(self, fit, items, rng):
            return None

    result = residual_structure(Table(), None, np.arange(3), base_mse=1.0, rng=np.random.default_rng(0))
    assert not result["structure_remains"] and result["summary"].startswith("not tested")


class SettingsTable:
    """Held-out rows of a table: one residual value per row and the row's settings (name -> value per row)."""

    def __init__(self, residual: np.ndarray, settings: dict[str, np.ndarray]) -> None:
        self.residual, self.settings = residual, settings

    def residual_sample(self, fit, items, rng):
        return ResidualSample(
            [self.residual[i : i + 1] for i in items],
            {name: [values[i : i + 1] for i in items] for name, values in self.settings.items()},
        )


def beat_table(beat: float, seed: int = 0) -> SettingsTable:
    """Nine laser frequencies 15 Hz apart, seen 3-5 times each, and a residual that beats with a 30 Hz frame rate -
    its sign alternates between neighbouring frequencies - plus noise."""
    rng = np.random.default_rng(seed)
    frequency = np.repeat(30.0 + 15.0 * np.arange(9), [3, 4, 3, 5, 3, 4, 3, 4, 3])
    residual = beat * np.cos(2 * np.pi * frequency / 30.0) + rng.normal(0.0, 0.02, len(frequency))
    return SettingsTable(residual, {"frequency_hz": frequency})


def test_a_beat_across_the_levels_of_a_setting_is_explained_level_by_level():
    """Nine levels are more than 8 quantile bins: merged, two neighbouring levels would cancel. Each level is its
    own bin, so the level means explain all of the residual but its noise; noise alone stays below chance."""
    table = beat_table(beat=1.0)
    frequency = table.settings["frequency_hz"]
    result = residual_structure(table, None, np.arange(32), base_mse=1.0, rng=np.random.default_rng(0))
    (test,) = result["tests"]
    assert result["structure_remains"] and test["value"] > 0.99, test
    per_level = binned_rmse(frequency, table.residual)
    assert per_level["x"] == sorted(set(frequency.tolist()))
    assert per_level["count"] == [3, 4, 3, 5, 3, 4, 3, 4, 3]
    assert per_level["rmse"] == pytest.approx([1.0] * 9, abs=0.05)  # |beat| = 1 at every level, noise 0.02
    noise = residual_structure(
        beat_table(beat=0.0), None, np.arange(32), base_mse=1.0, rng=np.random.default_rng(0)
    )
    assert not noise["structure_remains"], noise["summary"]


def noise_table(variables: int, rows: int = 24, seed: int = 0) -> SettingsTable:
    """A noise residual and ``variables`` settings of 12 levels each, unrelated to it."""
    rng = np.random.default_rng(seed)
    residual = rng.normal(0.0, 1.0, rows)
    return SettingsTable(
        residual, {f"setting_{k}": rng.integers(0, 12, rows).astype(float) for k in range(variables)}
    )


def test_chance_is_judged_over_all_the_variables_tested():
    """With k variables the chance level is the permutation null's 1 - 0.01 / k quantile (Bonferroni), so the
    same noisy setting must clear a higher bar when it is one of ten settings tested than when it is alone."""
    alone = residual_structure(
        noise_table(1), None, np.arange(24), base_mse=1.0, rng=np.random.default_rng(0)
    )
    among_ten = residual_structure(
        noise_table(10), None, np.arange(24), base_mse=1.0, rng=np.random.default_rng(0)
    )
    first_alone, first_among_ten = alone["tests"][0], among_ten["tests"][0]
    assert first_alone["variable"] == first_among_ten["variable"] == "setting_0"
    assert first_alone["chance_quantile"] == pytest.approx(0.99)
    assert first_among_ten["chance_quantile"] == pytest.approx(0.999)
    # 24 rows in up to 12 levels: chance alone explains a large share of noise, and more at a stricter quantile
    assert 0.5 < first_alone["chance"] < first_among_ten["chance"] < 1.0
    assert not among_ten["structure_remains"], among_ten["summary"]


class ItemTable:
    """One value per item: residuals of a table whose fitted model is right (noise) except on ``broken`` items."""

    def __init__(self, n: int, broken: dict[int, float], seed: int) -> None:
        self.residuals = np.random.default_rng(seed).normal(0.0, 2.0, n)
        for item, error in broken.items():
            self.residuals[item] = error

    def item_label(self, item: int) -> str:
        return f"row {item}"

    def item_squared_errors(self, fit, items):
        return self.residuals[items] ** 2, np.ones(len(items))

    def residual_sample(self, fit, items, rng):
        return ResidualSample(
            [np.array([r]) for r in self.residuals[items]], {"setting": [np.array([i]) for i in items]}
        )


@pytest.mark.parametrize("seed", range(5))
def test_a_few_held_out_items_outside_the_fit_errors_are_reported_by_name(seed):
    """Three held-out rows a model cannot predict (errors of 80-230 where the fit rows err by a few): the finding
    names them and their share of the squared error; the same table without them reports nothing."""
    fit_items, heldout = np.arange(90), np.arange(90, 112)
    broken = ItemTable(112, {95: 231.6, 99: 132.2, 104: 80.3}, seed)
    rng = np.random.default_rng(seed)
    result = residual_structure(broken, None, heldout, base_mse=191.0**2, rng=rng, fit_items=fit_items)
    items = next(t for t in result["tests"] if t["variable"] == "items")
    assert result["structure_remains"] and items["significant"], result["summary"]
    assert sorted(items["outlying_items"]) == [95, 99, 104]
    assert "row 95: 232" in result["summary"] and "the model fails on a few items" in result["summary"]
    clean = ItemTable(112, {}, seed)
    result = residual_structure(clean, None, heldout, base_mse=191.0**2, rng=rng, fit_items=fit_items)
    assert not result["structure_remains"], result["summary"]
    assert next(t for t in result["tests"] if t["variable"] == "items")["outlying_items"] == []


@pytest.mark.parametrize("spread_px", [0.0, 1.0, 2.0])
def test_light_spread_across_the_pattern_edges_is_reported_as_dependence_on_pattern_detail(spread_px):
    problem = ProjectionFrames(
        projection_pairs_with_spread_light(spread_px), seed=0, pattern_record="captured"
    )
    fit = Fit(frozenset({"additive_light"}), {"strength": 0.4})
    result = residual_structure(problem, fit, np.arange(6), base_mse=1.0, rng=np.random.default_rng(0))
    detail = next(t for t in result["tests"] if t["variable"] == "pattern_detail")
    if spread_px == 0.0:
        assert not result["structure_remains"], result["summary"]
    else:
        # predicted minus measured: the sharp pattern's light, too much on the bright side of an edge
        assert detail["significant"] and detail["r"]["estimate"] > 0.5, detail
        assert "depends on pattern_detail" in result["summary"]


def structure_with_band_of_rows(band: Callable[[int, np.random.Generator], np.ndarray]) -> dict:
    """The residual structure of additive light at its true strength on projection pairs whose rows 10-19 carry
    ``band(pair_index, rng)`` (channels, 10, 50) on top: zero-mean noise, which the mean tests cannot see."""
    pairs = projection_pairs_with_spread_light(0.0)
    rng = np.random.default_rng(5)
    for index, pair in enumerate(pairs):
        extra = np.zeros(pair.attacked.shape)
        extra[:, 10:20] = band(index, rng)
        pair.attacked = (pair.attacked + torch.from_numpy(extra)).clamp(0, 1)
    problem = ProjectionFrames(pairs, seed=0, pattern_record="captured")
    fit = Fit(frozenset({"additive_light"}), {"strength": 0.4})
    return residual_structure(problem, fit, np.arange(6), base_mse=1.0, rng=np.random.default_rng(0))


@pytest.mark.parametrize("band_noise", [0.0, 0.016])
def test_zero_mean_noise_in_a_band_of_rows_is_reported_as_variance_by_row(band_noise):
    # speckle-like: noise on rows 10-19 only, four times the frames' own
    result = structure_with_band_of_rows(
        lambda _, rng: rng.normal(0.0, band_noise, (3, 10, 50)) if band_noise else 0.0
    )
    tests = {t["variable"]: t for t in result["tests"]}
    # chance is judged over the family of all eight variables: six of the mean, two of the variance
    assert (
        tests["row"]["chance_quantile"] == tests["variance_by_row"]["chance_quantile"] == 1 - FAMILY_ALPHA / 8
    )
    assert not tests["row"]["significant"] and not tests["column"]["significant"], result["summary"]
    assert not tests["variance_by_column"]["significant"], tests["variance_by_column"]
    if not band_noise:
        assert not result["structure_remains"], result["summary"]
    else:
        by_row = tests["variance_by_row"]
        assert by_row["significant"] and by_row["interval"]["low"] > 0.1, by_row
        # rows 10-19 of 40 are 0.26-0.49 of the frame's height
        assert "for values 0.2" in by_row["where"] or "for values 0.3" in by_row["where"], by_row["where"]
        assert "variance beyond sensor noise depends on row" in result["summary"]
        # the finding's size (grey levels^2, base MSE 1): the band's extra variance, (0.016 * 255)^2, held by two of
        # the eight row bins, is 16.6 * sqrt(2 / 8) = 8.3 as the bins' root mean square
        assert 8.3 / 2 < by_row["share_of_base_mse"] < 8.3 * 2, by_row


@pytest.mark.parametrize("strength, lowest", [(0.0, None), (0.016, 0.02), (0.03, 0.06)])
def test_speckle_whose_strength_differs_between_pairs_is_reported_as_variance_by_row(strength, lowest):
    # laser speckle on a band of rows: the light's exponential fluctuation (contrast 1), its strength growing from
    # pair to pair and fading from the band's centre, as camsim's strip speckle's does. Squared residuals leave
    # the pairs' largest values to carry eta2, so an item bootstrap without the strongest pair loses it: their low
    # end stayed near 0.013 at both strengths, under the 0.02 floor (0.025 and 0.071 in the absolute form)
    shares = [0.05, 0.1, 0.2, 0.4, 0.7, 1.0]
    fade = np.exp(-0.5 * ((np.arange(10) - 4.5) / 3) ** 2)[:, None]
    result = structure_with_band_of_rows(
        lambda index, rng: strength * shares[index] * fade * (rng.exponential(1.0, (1, 10, 50)) - 1.0)
    )
    by_row = next(t for t in result["tests"] if t["variable"] == "variance_by_row")
    if lowest is None:
        assert not by_row["significant"], by_row
    else:
        assert by_row["significant"] and by_row["interval"]["low"] > lowest, by_row
        assert "variance beyond sensor noise depends on row" in result["summary"]


def test_frames_clipped_everywhere_leave_no_variance_to_test():
    # every attacked value at the white level: sensor noise cannot be read, and the test says nothing, not crash
    pairs = projection_pairs_with_spread_light(0.0)
    for pair in pairs:
        pair.attacked = torch.ones_like(pair.attacked)
    problem = ProjectionFrames(pairs, seed=0, pattern_record="captured")
    fit = Fit(frozenset({"additive_light"}), {"strength": 0.4})
    result = residual_structure(problem, fit, np.arange(6), base_mse=1.0, rng=np.random.default_rng(0))
    assert not any(t["variable"].startswith("variance_by_") for t in result["tests"])
    assert any(t["variable"] == "row" for t in result["tests"])


@pytest.mark.parametrize("slip_px", [0.0, 0.7, -0.7])
def test_rows_arriving_displaced_are_reported_with_their_displacement(slip_px):
    # rows 8-31 of each attacked frame hold the content slip_px further along the row (scipy's spline shift, not
    # the package's): predicted - measured ~ -slip * the prediction's gradient, a mean of zero in every row
    pairs = projection_pairs_with_spread_light(0.0)
    for pair in pairs:
        attacked = pair.attacked.numpy().copy()
        attacked[:, 8:32] = ndimage.shift(attacked[:, 8:32], (0, 0, -slip_px), order=3, mode="nearest")
        pair.attacked = torch.from_numpy(attacked)
    problem = ProjectionFrames(pairs, seed=0, pattern_record="captured")
    fit = Fit(frozenset({"additive_light"}), {"strength": 0.4})
    result = residual_structure(problem, fit, np.arange(6), base_mse=1.0, rng=np.random.default_rng(0))
    tests = {t["variable"]: t for t in result["tests"]}
    along_rows, along_columns = tests["displacement_along_rows"], tests["displacement_along_columns"]
    assert not along_columns["significant"], along_columns
    if not slip_px:
        assert not result["structure_remains"], result["summary"]
        assert abs(along_rows["displacement_px"]["estimate"]) < 0.02, along_rows
    else:
        assert along_rows["significant"] and along_rows["interval"]["low"] > 0.2, along_rows
        # the pattern's edges, where the gradient is, lie mostly in the displaced rows: d is most of the slip
        assert 0.6 < along_rows["displacement_px"]["estimate"] / slip_px < 1.1, along_rows["displacement_px"]
        # rows 8-31 of 40 are 0.2-0.8 of the frame's height; the largest displacement is in one of their bins
        assert any(f"rows at {low}-" in along_rows["where"] for low in ("0.25", "0.375", "0.5", "0.625"))
        assert "the rows are displaced from the prediction" in result["summary"]


def test_a_displacement_read_in_each_half_of_a_line_is_not_found_in_noise():
    # on residuals that do not follow the gradient the two halves' readings are independent: the share is about 0
    # however neighbouring residuals correlate (smoothed noise), while in sample a coefficient per line explains
    # some of the residual by chance
    rng = np.random.default_rng(3)
    predicted = ndimage.gaussian_filter(rng.uniform(0, 255, (3, 40, 60)), sigma=(0, 1.5, 1.5))
    shares = []
    for _ in range(20):
        residual = ndimage.gaussian_filter(rng.normal(0, 3, (3, 40, 60)), sigma=(0, 1, 1))
        terms = line_terms(residual, predicted)["rows"]
        explained, total = displacement_columns(terms)[:2]
        in_sample = np.sum((terms[:, 0] + terms[:, 2]) ** 2 / (terms[:, 1] + terms[:, 3]))
        shares.append((explained / total, in_sample / total))
    halves, in_sample = np.array(shares).T
    assert abs(np.mean(halves)) < 0.2 * np.mean(in_sample) and np.all(halves < in_sample), (halves, in_sample)
    # a whole-frame shift of 0.5 px: both halves read it, and the share is most of the residual
    shifted = ndimage.shift(predicted, (0, 0, -0.5), order=3, mode="nearest")
    terms = line_terms(predicted - shifted, predicted)["rows"]
    explained, total = displacement_columns(terms)[:2]
    assert explained / total > 0.5, explained / total
    # no line's term exceeds its own sum of squared residuals, however unequal its halves' gradients: an edge in the
    # first block of each row, and a prediction nearly flat elsewhere
    lopsided = np.tile(np.where(np.arange(60) < 4, 200.0, 0.0), (3, 40, 1)) + rng.normal(0, 0.01, (3, 40, 60))
    for line in line_terms(rng.normal(0, 3, (3, 40, 60)), lopsided)["rows"]:
        assert abs(displacement_columns(line[None])[0]) <= line[4], line
