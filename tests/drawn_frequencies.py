"""One check shared by the transform's and the calibration's tests: values drawn from a discrete law."""

from __future__ import annotations

import numpy as np


def assert_frequencies_follow(drawn: np.ndarray, values: np.ndarray, probabilities: np.ndarray) -> None:
    """Every drawn value is one the law allows, and each allowed value's frequency is within 4.5 standard errors
    of its probability (a binomial share; 1e-4 more for a probability of 0 or 1)."""
    drawn = np.asarray(drawn)
    seen, frequency = np.unique(drawn, return_counts=True)
    assert set(seen.tolist()) <= set(np.asarray(values).tolist()), (seen, values)
    observed = np.array([frequency[seen.tolist().index(v)] if v in seen else 0 for v in values]) / len(drawn)
    tolerance = 4.5 * np.sqrt(probabilities * (1 - probabilities) / len(drawn)) + 1e-4
    assert (np.abs(observed - probabilities) <= tolerance).all(), (observed, probabilities)
