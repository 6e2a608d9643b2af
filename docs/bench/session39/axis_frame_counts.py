"""Frames behind each row of a "They See Me Rollin'" stripe table (read by path, not in this repository): n = (z *
affected_rows_std / half-width)^2 from the 95% half-width (z = 1.96), summarised per exposure setting as the smallest
and largest count and the count at each duty of 20% and above. Prints derived counts only, no measured value.

Usage: ``python docs/bench/session39/axis_frame_counts.py TABLE.csv``
"""

import sys

import numpy as np
import pandas as pd


def main(path: str) -> None:
    table = pd.read_csv(path)
    frames = (1.959964 * table["affected_rows_std"] / table["affected_rows_95ci"]) ** 2
    table = table.assign(frames=frames)
    for exposure, rows in table.groupby("exposure", sort=False):
        wide = rows[rows["duty_cycle"] >= 20].sort_values("duty_cycle")
        cells = ", ".join(f"{d:g}%: {n:.0f}" for d, n in zip(wide["duty_cycle"], wide["frames"], strict=True))
        print(f"{exposure}: {np.min(rows['frames']):.0f}-{np.max(rows['frames']):.0f} frames; {cells}")


if __name__ == "__main__":
    main(sys.argv[1])
