"""Where a warm-started fit starts (``core.further_starts``): an extension also from the defaults (a nested model's
saturated values can stall it), a bootstrap refit of the same model from its estimate only; frame pairs
(``frame_models.common.PixelProblem.fit``) and colour triples (``projection.TripleProblem.fit``) follow it."""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration import projection
from lerobot_phantom.calibration.core import Fit, Param, further_starts
from lerobot_phantom.calibration.example import write_example
from lerobot_phantom.calibration.frame_models import common
from lerobot_phantom.calibration.frame_models.common import Pair, PixelProblem


class Brightened(PixelProblem):
    """attacked = gain * clean (+ offset with the ``offset`` effect)."""

    def features(self, index, pixels):
        return {"clean": common.flat_pixels(self.pairs[index].clean, pixels)}

    def predict_features(self, effects, params, feats):
        out = params["gain"] * feats["clean"]
        return out + params["offset"] if "offset" in effects else out

    def param_specs(self, effects):
        specs = [Param("gain", 1.0, 0.0, 4.0)]
        return specs + ([Param("offset", 0.0, -1.0, 1.0, scale=0.1)] if "offset" in effects else [])


def problem() -> Brightened:
    g = torch.Generator().manual_seed(0)
    pairs = []
    for i in range(4):
        clean = torch.rand(3, 8, 8, generator=g, dtype=torch.float64) * 0.5
        pairs.append(Pair(f"p{i}", clean, (1.5 * clean + 0.1).clamp(max=1.0), None, 1.0))
    return Brightened(pairs, seed=0)


def recorded_fits(monkeypatch, module) -> list[dict]:
    """The keyword arguments of every ``fit_least_squares`` call made through ``module`` (the fits still run)."""
    calls = []
    real = module.fit_least_squares

    def recorded(specs, residuals, **kwargs):
        calls.append(kwargs)
        return real(specs, residuals, **kwargs)

    monkeypatch.setattr(module, "fit_least_squares", recorded)
    return calls


def test_extensions_also_start_from_the_defaults_refits_only_from_the_estimate(monkeypatch):
    calls = recorded_fits(monkeypatch, common)
    toy, items = problem(), np.arange(4)
    base = toy.fit(frozenset(), items)
    extended = toy.fit(frozenset({"offset"}), items, start=base)
    refit = toy.fit(frozenset({"offset"}), items[[0, 0, 1, 3]], start=extended)
    assert [c["starts"] for c in calls] == [[], [{}], []]
    assert calls[2]["warm"] == extended.params
    # the refit still finds the model's optimum on its resample
    assert abs(refit.params["gain"] - 1.5) < 1e-6 and abs(refit.params["offset"] - 0.1) < 1e-6


def test_further_starts_rule():
    nested = Fit(frozenset(), {"alpha": 0.5})
    assert further_starts(None, frozenset({"a"})) == []
    assert further_starts(nested, frozenset({"a"})) == [{}]
    assert further_starts(nested, frozenset()) == []  # a refit of the same model
    # a nested model without parameters: its warm start is the defaults already
    assert further_starts(Fit(frozenset(), {}), frozenset({"a"})) == []


def test_colour_triple_refits_start_from_the_estimate_only(monkeypatch, tmp_path):
    """Fails on the code before the rule moved to core: projection refits also started from the defaults."""
    calls = recorded_fits(monkeypatch, projection)
    triples = projection.TripleProblem(write_example(tmp_path, rows=120))
    items = np.arange(triples.n_items)
    base = triples.fit(frozenset(), items)
    extended = triples.fit(frozenset({"additive_light"}), items, start=base)
    triples.fit(frozenset({"additive_light"}), items[::2], start=extended)
    assert [c["starts"] for c in calls] == [[], [{}], []]
