"""The drift kernel's two starts on the Axis camera's exposure-50 sweep (25 Hz laser, 720-row frames, duty 5-30%):
mean lit rows per counted frame against the drift, from any whole placement and from the entry.

Camera parameters are session 28's fit of the Axis table on split seed 0 (row time 20.30 us, integration offset
302.6 us; ``docs/bench/session28/axis_table_seeds_766ee13.json``). Prints kernel values only, never the table's.
Usage: ``python docs/bench/session33/exposure50_kernel.py``.
"""

import torch

from lerobot_phantom.transforms import physics

ROW_TIME_S, OFFSET_S = 2.0299e-5, 3.026e-4
DUTIES = torch.tensor([0.05, 0.10, 0.15, 0.20, 0.25, 0.30], dtype=torch.float64)

print(
    "drift  "
    + "  ".join(
        f"{start}: duty {', '.join(f'{100 * d:.0f}%' for d in DUTIES)}" for start in ("placement", "entry")
    )
)
for drift in (0.0, 0.05, 0.1, 0.2, 0.3, 0.32, 0.35, 0.4):
    cells = []
    for start in ("placement", "entry"):
        rows = physics.rolling_shutter_rows_lit(
            torch.full((6,), 25.0, dtype=torch.float64),
            DUTIES,
            torch.full((6,), 50e-6, dtype=torch.float64),
            ROW_TIME_S,
            image_rows=720,
            integration_offset_s=OFFSET_S,
            frames="interior",
            drift=torch.full((6,), drift, dtype=torch.float64),
            drift_start=start,
        )
        cells.append(" ".join(f"{float(r):5.0f}" for r in rows))
    print(f"{drift:5.2f}  " + "   |   ".join(cells))
