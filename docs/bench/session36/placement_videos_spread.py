"""The drifting recordings of the drift-naming test's placement-start table for one STRIPES_SEED, against the
spread of one video's mean and the kernel from both starts.

For each drifting recording and duty: the table's video (the test's draw), the mean and standard deviation of 40
more videos from their own starts (placement), and the kernel at the true camera (threshold, read noise and
blooming as the simulator draws them) from a whole placement and from the entry.

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session36/placement_videos_spread.py SEED``
"""

import os
import sys
from pathlib import Path

import numpy as np
import torch

DUTIES = (2, 5, 10, 15, 20, 25, 30, 35)
VIDEOS = 40


def main(seed: int) -> None:
    os.environ["STRIPES_SEED"] = str(seed)  # read by the test module at import
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    from lerobot_phantom.transforms import physics

    rng = np.random.default_rng([seed, 7])
    camera = test_stripes.draw_camera(rng, "interior")
    drifts = np.zeros(5)
    drifts[rng.choice(5, 2, replace=False)] = rng.uniform(0.33, 0.67, 2)
    frequency = round(1.0 / (2.0 * camera["height"] * camera["row_time"]), 1)
    print(test_stripes.camera_summary(camera), f"laser {frequency} Hz, drifts {np.round(drifts, 3).tolist()}")
    for exposure, drift in zip(camera["exposures_us"], drifts, strict=True):
        # the table's videos, drawn in the test's order (drifting_table)
        table = [
            test_stripes.simulate_drifting_recordings(
                camera, (frequency, duty / 100, exposure * 1e-6), drift, rng, recordings=1, frames=24
            )[0]
            for duty in DUTIES
        ]
        if drift == 0:
            continue

        def kernel(start: str, exposure=exposure, drift=drift) -> np.ndarray:
            n = len(DUTIES)
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
                drift_start=start,
            ).numpy()

        placement, entry = kernel("placement"), kernel("entry")
        more = np.random.default_rng([seed, 99])
        print(f"exposure {exposure:g} us, drift {drift:.3f}")
        for k, duty in enumerate(DUTIES):
            videos = test_stripes.simulate_drifting_recordings(
                camera, (frequency, duty / 100, exposure * 1e-6), drift, more, recordings=VIDEOS, frames=24
            )
            print(
                f"  duty {duty:2d}%: table's video {table[k]:6.1f}, {VIDEOS} videos {videos.mean():6.1f} "
                f"sd {videos.std(ddof=1):5.1f}, kernel from a placement {placement[k]:6.1f}, from the entry "
                f"{entry[k]:6.1f}"
            )


if __name__ == "__main__":
    main(int(sys.argv[1]))
