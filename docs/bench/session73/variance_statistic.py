"""The variance-by-position test's statistic on camsim's residuals, two ways: the squared form before session 73
(``residual^2 / modelled variance - 1``) and Levene's absolute form since (``|residual| / modelled sd``, over its
mean, - 1). Reads the pickles of ``variance_probe.py`` (each variance test's input during one case's calibration)
and prints, per case and per call (held-out residual; fit items' cross-fitted residuals, which gate photon noise),
the low end of the 90% interval of eta2 by row and by column against the rule's bar max(0.02, chance).
Usage: ``PYTHONPATH=. python docs/bench/session73/variance_statistic.py PROBE_OUT``."""

import pickle
import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration import structure
from lerobot_phantom.calibration.noise import NoiseSample, fit_variance, model_variance


def squared_excess(noise: list) -> list[np.ndarray]:
    """The statistic before session 73: residual^2 / modelled variance - 1 (the package's noise model)."""
    joined = NoiseSample.join(noise)
    values = joined.residual**2 / model_variance(joined, fit_variance(joined, True)) - 1.0
    return np.split(values, np.cumsum([len(p.residual) for p in noise])[:-1])


def cells(call: dict, form: str) -> str:
    """Low ends by row and column: the squared form through the package's dependence test, the absolute form by
    the package's own ``variance_tests``."""
    rng = np.random.default_rng(0)
    if form == "squared":
        sample = structure.ResidualSample(squared_excess(call["noise"]), call["position"])
        tests = structure.dependence_tests(sample, lambda s: s, rng, family=call["family"])
    else:
        sample = structure.ResidualSample([], {}, noise=call["noise"], noise_position=call["position"])
        tests = structure.variance_tests(sample, call["base_mse"], rng, family=call["family"])
    out = []
    for t in tests:
        bar = max(structure.MIN_EXPLAINED, t["chance"])
        name = t["variable"].removeprefix("variance_by_")[:3]
        out.append(f"{name} {t['interval']['low']:.4f}{'*' if t['interval']['low'] > bar else ' '}")
    return " ".join(out)


def main() -> None:
    print("low end of eta2's 90% interval by row / column; * above max(0.02, chance)")
    print(f"{'seed case':46s} {'call':9s} {'squared':22s} | absolute (Levene)")
    for path in sorted(Path(sys.argv[1]).glob("*.pkl")):
        for call in pickle.loads(path.read_bytes()):
            if not call["noise"]:
                continue
            kind = "fit items" if "fit_items_structure" in call["caller"] else "held-out"
            print(
                f"{path.stem:46s} {kind:9s} {cells(call, 'squared'):22s} | {cells(call, 'absolute')}",
                flush=True,
            )


if __name__ == "__main__":
    main()
