"""How many frames each video of a "They See Me Rollin'" stripe table kept, solved exactly from its own columns.

``rsa/profile.py`` writes the kept frames' population std (numpy, ddof 0) and the half-width of a Student-t interval
on the mean (scipy ``sem``, ddof 1): ``h = std * t_{n-1} / sqrt(n - 1)``. The two columns fix ``n``; the 99% column
must give the same ``n``. Prints counts per sweep and duty only, never the table's values.

    python docs/bench/session40/axis_kept_frames.py TABLE.csv
"""

import sys

import numpy as np
import pandas as pd
from scipy import stats


def kept_frames(std: float, half_width: float, confidence: float) -> int:
    """The n at which std * t_{n-1} / sqrt(n - 1) is nearest half_width (scanned over 2..5000)."""
    n = np.arange(2, 5001)
    predicted = std * stats.t.ppf((1 + confidence) / 2, n - 1) / np.sqrt(n - 1)
    return int(n[np.argmin(np.abs(predicted - half_width))])


def main(path: str) -> None:
    table = pd.read_csv(path)
    table["duty"] = table["duty_cycle"].astype(float)
    for exposure, sweep in table.groupby("exposure", sort=False):
        cells = []
        for _, row in sweep.sort_values("duty").iterrows():
            n95 = kept_frames(row["affected_rows_std"], row["affected_rows_95ci"], 0.95)
            n99 = kept_frames(row["affected_rows_std"], row["affected_rows_99ci"], 0.99)
            cells.append(f"{row['duty']:g}%: {n95}" + ("" if n95 == n99 else f" (99% column: {n99})"))
        print(f"{exposure}: " + ", ".join(cells))


if __name__ == "__main__":
    main(sys.argv[1])
