"""CPU of the structure test's permutation null (2000 permutations, every variable scored on each): the scalar eta
squared of 1e70396 (``np.bincount`` of sums and counts, the sum of squares given) against the totals form of 926884e
(``binned_columns`` + ``explained_share_of_totals`` per variable), measured in one run on the same residuals.

    python docs/bench/session45/structure_null_cost.py [N_VALUES ...]
"""

import sys
import time

import numpy as np

from lerobot_phantom.calibration.core import bin_index
from lerobot_phantom.calibration.structure import binned_columns, explained_share_of_totals

PERMUTATIONS, VARIABLES = 2000, 5


def scalar_share(residual, bins, total):
    sums, counts = np.bincount(bins, weights=residual), np.bincount(bins)
    return float(np.sum(sums[counts > 0] ** 2 / counts[counts > 0]) / total)


def totals_share(residual, bins, n):
    return explained_share_of_totals(binned_columns(residual, bins, n)[None], n)[0]


for size in [int(a) for a in sys.argv[1:]] or [1000, 8000, 32000]:
    rng = np.random.default_rng(0)
    residual = rng.normal(size=size)
    bins = [bin_index(rng.uniform(size=size), 8)[0] for _ in range(VARIABLES)]
    n_bins = [int(b.max()) + 1 for b in bins]
    total = float(np.sum(residual**2))
    timings = {}
    for name, share in (
        ("scalar", lambda r, b, n, total=total: scalar_share(r, b, total)),
        ("totals", totals_share),
    ):
        draws = np.random.default_rng(1)
        start = time.process_time()
        for _ in range(PERMUTATIONS):
            permuted = draws.permutation(residual)
            [share(permuted, b, n) for b, n in zip(bins, n_bins, strict=True)]
        timings[name] = time.process_time() - start
    print(
        f"{size} values x {VARIABLES} variables x {PERMUTATIONS} permutations: scalar {timings['scalar']:.2f} s, "
        f"totals {timings['totals']:.2f} s, ratio {timings['totals'] / timings['scalar']:.2f}"
    )
