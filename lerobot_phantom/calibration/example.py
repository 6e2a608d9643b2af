"""A measured-data example anyone can calibrate without ``../shared``: ``lerobot-phantom-calibrate
--make-example DIR`` writes ``DIR/projection_triples.csv``, a colour-triple table of a projector lighting a
coloured surface, rendered with physics the paper's alpha blend lacks (light adds to the surface's own light in
proportion to its reflectance, the sensor clips, 8-bit noise), then prints the command that calibrates it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

EXAMPLE_FILE = "projection_triples.csv"


def write_example(folder: Path, *, seed: int = 0, rows: int = 400) -> Path:
    """Write the example table into ``folder`` (created; an existing table is never overwritten)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / EXAMPLE_FILE
    if path.exists():
        raise FileExistsError(f"{path} exists; choose an empty --make-example directory")
    rng = np.random.default_rng(seed)
    surface = rng.uniform(0.05, 0.9, (rows, 3))
    projected = rng.choice([0.0, 0.5, 1.0], (rows, 3))
    strength, floor, white = 0.6, 0.15, 0.92
    captured = np.minimum(surface + strength * projected * (surface + floor), white)
    captured = np.clip(captured + rng.normal(0.0, 1.0 / 255.0, captured.shape), 0.0, 1.0)
    table = {}
    for kind, values in (("origin", surface), ("addition", projected), ("outcome", captured)):
        for c, channel in enumerate("rgb"):
            table[f"{kind}_{channel}"] = np.round(255 * values[:, c]).astype(int)
    pd.DataFrame(table).to_csv(path, index=False)
    return path
