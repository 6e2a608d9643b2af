"""camsim's auto-exposure meter taken apart: on each pair of a draw of camsim's auto-exposure blinding case, the
meter's factor ``k`` (the attacked frame's exposure over the clean one's) that camsim's own meter gives (the
centre-weighted mean of clipped luma), and what four meters give on the same light (camsim's true light in clean-frame
units, after its optics): luma or the pixel's channel mean (the package's statistic), each centre-weighted as
camsim's or uniform (the package's weighting). Medians over the draw's pairs; no calibration runs.

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests:docs/bench/session88:docs/bench/session90 python
docs/bench/session90/camsim_meter_parts.py CASE_SEED...``
"""

from __future__ import annotations

import sys

import camsim
import numpy as np
import test_independent_sim as sim
from blinding_exposure_sensitivity import record_captures


def solve(statistic: np.ndarray, target: float, weight: np.ndarray) -> float:
    """The factor at which the weighted mean of ``min(k statistic, 1)`` reads ``target`` (bisection on log k)."""
    low, high = np.log(1e-4), np.log(1e3)
    for _ in range(60):
        middle = (low + high) / 2
        if (np.minimum(np.exp(middle) * statistic, 1.0) * weight).sum() < target:
            low = middle
        else:
            high = middle
    return float(np.exp((low + high) / 2))


def main() -> None:
    calls = record_captures()  # (irradiance, camera, exposure asked or None, exposure used)
    statistics = {"luma": lambda x: x @ camsim.LUMA, "channel mean": lambda x: x.mean(2)}
    for seed in [int(s) for s in sys.argv[1:]]:
        calls.clear()
        case = sim.CASE_BY_NAME["blinding_auto_exposure"]
        _, rng, cam = sim.case_camera(case, seed)
        case.render(rng, cam)
        attacked_calls = [k for k, c in enumerate(calls) if c[2] is None]
        clean_calls = [0] + [k - 1 for k in attacked_calls[1:]]
        ys, xs = np.mgrid[0 : cam.height, 0 : cam.width].astype(float)
        centre = np.exp(
            -(
                ((ys - cam.height / 2) / (0.6 * cam.height)) ** 2
                + ((xs - cam.width / 2) / (0.6 * cam.width)) ** 2
            )
        )
        weights = {
            "centre-weighted": centre / centre.sum(),
            "uniform": np.full(centre.shape, 1.0 / centre.size),
        }
        rows = []
        for attacked, clean in zip(attacked_calls, clean_calls, strict=True):
            exposure = calls[clean][3]
            light = exposure * camsim.optics(calls[attacked][0], cam)
            scene = exposure * camsim.optics(calls[clean][0], cam)
            row = {"camsim": calls[attacked][3] / exposure}
            for statistic_name, statistic in statistics.items():
                for weight_name, weight in weights.items():
                    target = float((np.minimum(statistic(scene), 1.0) * weight).sum())
                    row[f"{statistic_name}, {weight_name}"] = solve(statistic(light), target, weight)
            rows.append(row)
        print(
            f"case seed {seed}: k, median over {len(rows)} pairs: "
            + ", ".join(f"{name} {np.median([r[name] for r in rows]):.3f}" for name in rows[0]),
            flush=True,
        )


if __name__ == "__main__":
    main()
