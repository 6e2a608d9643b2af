"""How often the flat-piece rounding of section 3 lights whole periods, with no threshold: conditions whose lit span
exceeds min(on + window, period) by more than a millionth, over the drift tests' tables of STRIPES_SEED 1-400 (no
integration offset) and over the Axis and Logitech tables (read by path, not in this repository) at the integration
offsets given.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session39/flat_piece_rounding_count.py AXIS_CSV
LOGITECH_CSV``
"""

import os
import sys
from pathlib import Path

import numpy as np
import torch


def over_lit(frequency: torch.Tensor, duty: torch.Tensor, window: torch.Tensor) -> torch.Tensor:
    from lerobot_phantom.transforms import physics

    period = 1.0 / frequency
    on = duty * period
    reached = physics.pulse_overlap_lit_time(period, on, window, 0.0, None)
    return reached > torch.minimum(on + window, period) * (1.0 + 1e-6)


def main(axis: Path, logitech: Path) -> None:
    os.environ.setdefault("STRIPES_SEED", "0")  # read by the test module at import
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    from lerobot_phantom.calibration.stripes import read_stripe_table

    tables, rows = 0, 0
    duties = torch.tensor([2, 5, 10, 15, 20, 25, 30, 35], dtype=torch.float64) / 100.0
    for seed in range(1, 401):
        _, camera, _ = test_stripes.drifting_draw(seed, drifting=True)
        frequency = round(1.0 / (2.0 * camera["height"] * camera["row_time"]), 1)
        window = torch.as_tensor(np.repeat(camera["exposures_us"] * 1e-6, len(duties)))
        hit = over_lit(torch.full_like(window, frequency), duties.repeat(5), window)
        tables += bool(hit.any())
        rows += int(hit.sum())
    print(
        f"drift-test tables, seeds 1-400, no offset: {tables} of 400 have a lit-whole row ({rows} of 16000 rows)"
    )
    for path, unit, offsets in ((axis, 1e-6, (0.0, 301e-6, 311e-6)), (logitech, 1e-4, (0.0, 303e-6, 350e-6))):
        _, meta = read_stripe_table(path, image_height=720, exposure_unit_s=unit)
        for offset in offsets:
            hit = over_lit(
                torch.as_tensor(meta["frequency_hz"]),
                torch.as_tensor(meta["duty"]),
                torch.as_tensor(meta["exposure_s"]) + offset,
            )
            print(f"{path.name}, offset {offset * 1e6:g} us: {int(hit.sum())} of {len(hit)} rows lit whole")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
