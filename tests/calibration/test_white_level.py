"""A light projection's clip is named the sensor's saturation only if the sensor's own clean frames stay under it
(``ProjectionTerms.identification_checks``): a colour-triple table."""

from __future__ import annotations

import numpy as np
from test_tables_and_captures import write_triple_table

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.projection import TripleProblem


def test_a_tables_surface_colours_bound_its_clip(tmp_path):
    """A table's surface colours are the clean colours its camera recorded: a white under most of them is not that
    camera's, one over all of them is."""
    rng = np.random.default_rng(3)
    surface = rng.uniform(0.05, 0.9, (200, 3))
    projected = rng.choice([0.0, 127 / 255, 254 / 255], (200, 3))
    problem = TripleProblem(write_triple_table(tmp_path / "t.csv", surface, projected, surface))
    items = np.arange(problem.n_items)
    for white, sensors in ((0.95, True), (0.3, False)):
        fit = Fit(frozenset({"clipping"}), {"opacity": 0.5, "white": white})
        assert (problem.identification_checks("clipping", fit, items) == []) is sensors
