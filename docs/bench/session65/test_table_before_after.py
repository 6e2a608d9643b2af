"""The rippled and plain one-material tables of ``test_tables_and_captures.py`` (its generator copied at 8f0df60),
calibrated by the package on ``PYTHONPATH``: run with ``PYTHONPATH`` at a checkout of bbe5bab (before) and of 8f0df60
(after). Prints the package's path, then per table the written effects, the held-out RMSE and the structure summary.
"""

import tempfile
from pathlib import Path

import numpy as np

import lerobot_phantom
from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.projection import TRIPLE_COLUMNS


def write_triple_table(path, surface, projected, captured):
    data = np.round(np.concatenate([surface, projected, captured], axis=1) * 255).astype(int)
    path.write_text(
        ",".join(TRIPLE_COLUMNS) + "\n" + "\n".join(",".join(map(str, row)) for row in data) + "\n"
    )
    return path


def one_material_table(path, ripple):
    rng = np.random.default_rng(7)
    levels = np.array([0.0, 127 / 255, 254 / 255])
    projected = np.repeat(np.stack(np.meshgrid(levels, levels, levels), -1).reshape(-1, 3), 60, axis=0)
    surface = np.array([0.35, 0.55, 0.35]) + rng.uniform(-6, 6, projected.shape) / 255
    hue = 255 * (surface[:, 0] - surface[:, 1])
    strength = 0.4 * (1 + ripple * np.sin(2 * np.pi * hue / 30))
    noise = rng.normal(0, 1 / 255, projected.shape)
    captured = np.clip(surface + strength[:, None] * projected + noise, 0, 1)
    return write_triple_table(path, surface, projected, captured)


def main() -> None:
    print(lerobot_phantom.__file__)
    with tempfile.TemporaryDirectory() as tmp:
        for ripple in (0.5, 0.0):
            table = one_material_table(Path(tmp) / "t.csv", ripple)
            report = calibrate(
                CalibrateConfig(
                    attack="light_projection", measured=str(table), out=str(Path(tmp) / f"o{ripple}")
                )
            )
            summary = report["unexplained_structure"]["summary"]
            print(
                ripple,
                report["extended"]["effects"],
                round(report["extended"]["heldout_rmse"], 2),
                summary[:200],
            )


if __name__ == "__main__":
    main()
