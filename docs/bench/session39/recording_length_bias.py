"""The drifting recordings of the drift tests' placement-start table for one STRIPES_SEED: the kernel from a long
recording (the arc's limit, what it computed before session 39) and from the simulator's own 24 frames, against
the mean of many simulated 24-frame videos; then the kernel alone at other recording lengths.

For each drifting recording and duty: the mean and standard error of ``VIDEOS`` simulated videos (their own starts,
the test simulator's camera as drawn: rise time, read noise, blooming), the kernel at the true camera with
``recording_frames=None`` and ``=24``, and each one's gap in standard errors. The last lines count, per kernel, the
duties where the simulated mean lies more than 2 standard errors above or below it. Then, without the simulator,
the kernel at 6, 12, 24, 48, 96 and 384 frames and the long limit for the same conditions.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session39/recording_length_bias.py SEED [VIDEOS]``
"""

import os
import sys
from pathlib import Path

import numpy as np
import torch

DUTIES = (2, 5, 10, 15, 20, 25, 30, 35)
FRAMES = 24  # the test simulator's videos


def main(seed: int, videos: int) -> None:
    os.environ["STRIPES_SEED"] = str(seed)  # read by the test module at import
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    from lerobot_phantom.transforms import physics

    _, camera, drifts = test_stripes.drifting_draw(seed, drifting=True)
    frequency = round(1.0 / (2.0 * camera["height"] * camera["row_time"]), 1)
    print(test_stripes.camera_summary(camera), f"laser {frequency} Hz, drifts {np.round(drifts, 3).tolist()}")
    n = len(DUTIES)

    def kernel(exposure: float, drift: float, frames: int | None) -> np.ndarray:
        return physics.rolling_shutter_rows_lit(
            torch.full((n,), frequency, dtype=torch.float64),
            torch.tensor(DUTIES, dtype=torch.float64) / 100,
            torch.full((n,), exposure * 1e-6, dtype=torch.float64),
            camera["row_time"],
            image_rows=camera["height"],
            integration_offset_s=camera["offset"],
            threshold_s=camera["threshold_grey"] / camera["gain"],
            noise_s=camera["read_noise"] / camera["gain"],
            spread_rows=camera["spread"],
            frames="interior",
            drift=torch.full((n,), float(drift), dtype=torch.float64),
            recording_frames=frames,
        ).numpy()

    gaps: dict[str, list[float]] = {"long": [], f"{FRAMES} frames": []}
    more = np.random.default_rng([seed, 99])
    for exposure, drift in zip(camera["exposures_us"], drifts, strict=True):
        if drift == 0:
            continue
        long, own = kernel(exposure, drift, None), kernel(exposure, drift, FRAMES)
        print(f"exposure {exposure:g} us, drift {drift:.3f}")
        for k, duty in enumerate(DUTIES):
            simulated = test_stripes.simulate_drifting_recordings(
                camera,
                (frequency, duty / 100, exposure * 1e-6),
                drift,
                more,
                recordings=videos,
                frames=FRAMES,
            )
            error = simulated.std(ddof=1) / np.sqrt(videos)
            gaps["long"].append((simulated.mean() - long[k]) / error)
            gaps[f"{FRAMES} frames"].append((simulated.mean() - own[k]) / error)
            print(
                f"  duty {duty:2d}%: {videos} videos {simulated.mean():7.2f} +- {error:4.2f}; kernel long "
                f"{long[k]:7.2f} ({gaps['long'][-1]:+5.1f} se), {FRAMES} frames {own[k]:7.2f} "
                f"({gaps[f'{FRAMES} frames'][-1]:+5.1f} se)"
            )
    for name, values in gaps.items():
        values = np.array(values)
        print(
            f"kernel {name}: simulated mean above it by > 2 se on {int((values > 2).sum())} of {len(values)} duties, "
            f"below on {int((values < -2).sum())}; median {np.median(values):+.2f} se"
        )
    print("the kernel alone, rows per lit frame at recording lengths (frames) and the long limit:")
    lengths = (6, 12, 24, 48, 96, 384, None)
    for exposure, drift in zip(camera["exposures_us"], drifts, strict=True):
        if drift == 0:
            continue
        table = np.stack([kernel(exposure, drift, frames) for frames in lengths])
        for k, duty in enumerate(DUTIES):
            cells = " ".join(f"{v:7.2f}" for v in table[:, k])
            print(f"  exposure {exposure:g} us duty {duty:2d}%: {cells}  ({' '.join(map(str, lengths))})")


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 200)
