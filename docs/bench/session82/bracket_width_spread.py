"""Spread of the stripe width (integration offset - 2 x threshold) that the bracketed-threshold fit of
tests/calibration/test_stripes.py reaches, over fresh noise draws: what a tolerance on it must allow.

Usage: PYTHONPATH=. python docs/bench/session82/bracket_width_spread.py DRAWS"""

import os
import secrets
import sys
import tempfile
from pathlib import Path

sys.path[:0] = ["tests/calibration", "tests"]
os.environ.setdefault("STRIPES_SEED", "0")  # the module reads it at import; each draw here has its own seed

import numpy as np  # noqa: E402
import test_stripes  # noqa: E402


def main(draws: int) -> None:
    errors = []
    for _ in range(draws):
        seed = secrets.randbelow(2**32)
        widths = []
        for start_us in (20.0, 30.0, 46.0):
            with tempfile.TemporaryDirectory() as folder:
                truth, _, fit = test_stripes.fit_from_threshold_start(
                    Path(folder), np.random.default_rng([seed, 52]), start_us
                )
            widths.append(fit.params["integration_offset_s"] - 2 * fit.params["threshold_s"])
        truth_width = truth["integration_offset_s"] - 2 * truth["threshold_s"]
        errors.append((widths[0] - truth_width) * 1e6)
        print(
            f"seed {seed}: width - truth {errors[-1]:+.3f} us; starts 20/30/46 us differ by "
            f"{(max(widths) - min(widths)) * 1e6:.2e} us",
            flush=True,
        )
    errors = np.asarray(errors)
    print(
        f"{draws} draws: width - truth mean {errors.mean():+.3f} us, sd {errors.std(ddof=1):.3f} us, "
        f"max |.| {np.abs(errors).max():.3f} us, beyond 2 us {np.mean(np.abs(errors) > 2):.1%}"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]))
