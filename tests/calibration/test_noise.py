"""The shot-noise variance model on residuals with a known variance law (no CLI)."""

from __future__ import annotations

import numpy as np
import pytest

from lerobot_phantom.calibration.noise import fit_variance, mean_nll


def test_variance_law_is_recovered_and_beats_a_constant_only_when_present():
    rng = np.random.default_rng(0)
    signal = rng.uniform(5, 250, 40_000)
    read_var, gain = 4.0, 0.3
    shot_residual = rng.normal(0.0, 1.0, signal.shape) * np.sqrt(read_var + gain * signal)
    fitted_read, fitted_gain = fit_variance(signal, shot_residual, shot=True)
    assert fitted_read == pytest.approx(read_var, rel=0.3)
    assert fitted_gain == pytest.approx(gain, rel=0.1)
    constant = fit_variance(signal, shot_residual, shot=False)
    assert (
        mean_nll(signal, shot_residual, fitted_read, fitted_gain)
        < mean_nll(signal, shot_residual, *constant) - 0.05
    )

    flat_residual = rng.normal(0.0, 2.0, signal.shape)
    flat_read, flat_gain = fit_variance(signal, flat_residual, shot=True)
    assert flat_gain < 0.01
    assert flat_read == pytest.approx(4.0, rel=0.05)
