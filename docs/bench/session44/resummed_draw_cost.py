"""CPU seconds of 20 000 item-bootstrap totals (3 columns) drawn two ways, in one run: ``Generator.multinomial``
counts (the first form of ``identify.resummed_totals``, 104aed2) and counted drawn indices (its form since 8864213),
with their ratio, at several item counts. Single-threaded, alone on the machine:

    OMP_NUM_THREADS=1 PYTHONPATH=. python docs/bench/session44/resummed_draw_cost.py
"""

import time

import numpy as np

from lerobot_phantom.calibration.identify import RESUMMED_CHUNK, RESUMMED_DRAWS, resummed_totals


def multinomial_totals(columns: np.ndarray, draws: int, rng: np.random.Generator) -> np.ndarray:
    n_items = len(columns)
    totals = np.empty((draws, columns.shape[1]))
    chunk = max(1, RESUMMED_CHUNK // n_items)
    for start in range(0, draws, chunk):
        rows = min(chunk, draws - start)
        totals[start : start + rows] = (
            rng.multinomial(n_items, np.full(n_items, 1.0 / n_items), size=rows) @ columns
        )
    return totals


for n_items in (42, 300, 3000):
    columns = np.random.default_rng(0).uniform(size=(n_items, 3))
    started = time.process_time()
    multinomial_totals(columns, RESUMMED_DRAWS, np.random.default_rng(1))
    multinomial = time.process_time() - started
    started = time.process_time()
    resummed_totals(columns, draws=RESUMMED_DRAWS, rng=np.random.default_rng(1))
    counted = time.process_time() - started
    print(
        f"{n_items} items: multinomial {multinomial:.3f} s, counted indices {counted:.3f} s, "
        f"ratio {multinomial / counted:.2f}"
    )
