"""The drifting recordings of the drift-naming test's placement-start table for one STRIPES_SEED, against the
spread of one video's mean and the kernel from both starts.

For each drifting recording and duty: the table's video (the test's draw), the mean and standard deviation of 40
more videos from their own starts (placement), and the kernel at the true camera (threshold, read noise and
blooming as the simulator draws them) from a whole placement and from the entry. The last line counts the duties
where the 40-video mean and the placement kernel differ by more than 2 standard errors of that mean.

Camera values drawn for the seed can be replaced, e.g. ``rise=1e-9 read_noise=0 spread=0`` (a simulator without
the laser's rise time, read noise and blooming; the kernel is given the same camera).

Usage (from the checkout): ``PYTHONPATH=. python docs/bench/session36/placement_videos_spread.py SEED [KEY=VALUE ...]``
"""

import os
import sys
from pathlib import Path

import numpy as np
import torch

DUTIES = (2, 5, 10, 15, 20, 25, 30, 35)
VIDEOS = 40


def main(seed: int, overrides: dict[str, float]) -> None:
    os.environ["STRIPES_SEED"] = str(seed)  # read by the test module at import
    sys.path.insert(0, str(Path("tests/calibration").resolve()))
    import test_stripes

    from lerobot_phantom.transforms import physics

    rng, camera, drifts = test_stripes.drifting_draw(seed, drifting=True)
    unknown = set(overrides) - set(camera)
    if unknown:
        raise SystemExit(f"unknown camera keys {sorted(unknown)}; valid: {', '.join(sorted(camera))}")
    camera |= overrides
    frequency = round(1.0 / (2.0 * camera["height"] * camera["row_time"]), 1)
    print(test_stripes.camera_summary(camera), f"laser {frequency} Hz, drifts {np.round(drifts, 3).tolist()}")
    gaps = []  # (40-video mean - placement kernel) / its standard error, every drifting recording and duty
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
            gaps.append((videos.mean() - placement[k]) / (videos.std(ddof=1) / np.sqrt(VIDEOS)))
            print(
                f"  duty {duty:2d}%: table's video {table[k]:6.1f}, {VIDEOS} videos {videos.mean():6.1f} "
                f"sd {videos.std(ddof=1):5.1f}, kernel from a placement {placement[k]:6.1f}, from the entry "
                f"{entry[k]:6.1f}"
            )

    gaps = np.array(gaps)
    print(
        f"seed {seed}: the placement kernel is under the {VIDEOS}-video mean by more than 2 standard errors on "
        f"{int((gaps > 2).sum())} of {len(gaps)} duties, over it on {int((gaps < -2).sum())}; median gap "
        f"{np.median(gaps):+.2f} standard errors"
    )


def parse_override(text: str) -> tuple[str, float]:
    key, sep, value = text.partition("=")
    if not sep:
        raise SystemExit(f"camera override {text!r}: expected KEY=VALUE, e.g. read_noise=0")
    return key, (int(value) if key == "spread" else float(value))  # the simulator pads by a whole row count


if __name__ == "__main__":
    main(int(sys.argv[1]), dict(parse_override(a) for a in sys.argv[2:]))
