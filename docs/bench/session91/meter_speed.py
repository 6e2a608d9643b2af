"""The auto-exposure meter's cost, one run: session 90's channel-mean meter (``(n, P)``, one level per pixel, 12 Newton
steps), 3912454's luminance meter (the ``(n, 3, P)`` light read channel by channel, as the calibration passes it: a
transposed view of its ``(n * P, 3)`` probes), fc04f55's (a frame's channels in one row, stopped once Newton's steps
move ``k`` by rounding only) and the package's (``physics.metered_exposure``: after session 91's revert the channel
mean again, with that stop), on the calibration's shape (8 frames of ``METER_PROBES`` pixels, float64, one thread)
and on an attack's (a batch of 8 224x224 frames, float32, contiguous). Prints each one's time per call, its ratio to
session 90's, and the largest difference of fc04f55's exposures from 3912454's and of the package's from session
90's. (``meter_speed_fc04f55.txt`` is this script as at aa0747b, whose "package" was fc04f55's luminance meter.)

Usage: ``PYTHONPATH=. python docs/bench/session91/meter_speed.py``
"""

from __future__ import annotations

import time

import torch

from lerobot_phantom.calibration.frame_models.laser_blinding import METER_PROBES
from lerobot_phantom.transforms import physics

LUMA = (0.2126, 0.7152, 0.0722)  # Rec. 709


def channel_mean_meter(total: torch.Tensor, scene: torch.Tensor, steps: int = 12) -> torch.Tensor:
    """Session 90's ``physics.metered_exposure`` on ``(n, P)`` channel means."""
    target = scene.clamp(max=1.0).mean(1)
    k = torch.ones(len(total), dtype=total.dtype)
    for _ in range(steps):
        lit = (k[:, None] * total < 1.0).to(total.dtype)
        reading = torch.minimum(k[:, None] * total, torch.ones_like(total)).mean(1)
        slope = (total * lit).mean(1).clamp(min=1e-9)
        k = (k - (reading - target) / slope).clamp(1e-4, 10.0)
    return k


def channel_rows_meter(total: torch.Tensor, scene: torch.Tensor, steps: int = 12) -> torch.Tensor:
    """3912454's ``physics.metered_exposure``: the luminance of the clipped channels on ``(n, 3, P)`` as given."""
    weight = torch.tensor(LUMA, dtype=total.dtype).reshape(3, 1)
    target = (scene.clamp(max=1.0) * weight).sum(1).mean(1)
    k = torch.ones(len(total), dtype=total.dtype)
    for _ in range(steps):
        scaled = k[:, None, None] * total
        reading = (torch.minimum(scaled, torch.ones_like(total)) * weight).sum(1).mean(1)
        slope = (total * (scaled < 1.0).to(total.dtype) * weight).sum(1).mean(1).clamp(min=1e-9)
        k = (k - (reading - target) / slope).clamp(1e-4, 10.0)
    return k


def one_row_meter(total: torch.Tensor, scene: torch.Tensor, steps: int = 12) -> torch.Tensor:
    """fc04f55's ``physics.metered_exposure``: the luminance of the clipped channels, a frame's channels in one row,
    stopped once the steps move ``k`` by rounding only."""
    n, _, pixels = total.shape
    weight = torch.tensor(LUMA, dtype=total.dtype).div(pixels).repeat_interleave(pixels)
    total = total.reshape(n, -1)
    target = scene.reshape(n, -1).clamp(max=1.0) @ weight
    weighted = total * weight
    k = torch.ones(n, dtype=total.dtype)
    for _ in range(steps):
        scaled = k[:, None] * total
        reading = scaled.clamp(max=1.0) @ weight
        slope = torch.where(scaled < 1.0, weighted, 0.0).sum(1).clamp(min=1e-9)
        stepped = (k - (reading - target) / slope).clamp(1e-4, 10.0)
        settled = bool(((stepped - k).abs() <= 8 * torch.finfo(k.dtype).eps * k).all())
        k = stepped
        if settled:
            break
    return k


def per_call_ms(meter, total, scene, calls: int) -> float:
    meter(total, scene)
    start = time.perf_counter()
    for _ in range(calls):
        meter(total, scene)
    return (time.perf_counter() - start) / calls * 1e3


def light(frames: int, pixels: int, dtype, seed: int, probes: bool) -> tuple[torch.Tensor, torch.Tensor]:
    """``(frames, 3, pixels)`` blinded and scene light: as the calibration's probes give them (``probes``, a
    transposed view) or as an attack's frames do (contiguous)."""
    generator = torch.Generator().manual_seed(seed)
    scene = torch.rand(frames, pixels, 3, generator=generator, dtype=dtype) * 0.8
    laser = torch.zeros_like(scene)
    laser[:, : pixels // 10] = torch.tensor(
        [30.0, 4.0, 0.5], dtype=dtype
    )  # a red spot, its red far past white
    total, scene = (scene + laser).transpose(1, 2), scene.transpose(1, 2)
    return (total, scene) if probes else (total.contiguous(), scene.contiguous())


def main() -> None:
    torch.set_num_threads(1)
    for label, frames, pixels, dtype, calls, probes in (
        ("calibration, 8 x METER_PROBES float64", 8, METER_PROBES, torch.float64, 300, True),
        ("attack, 8 x 224 x 224 float32", 8, 224 * 224, torch.float32, 10, False),
    ):
        total, scene = light(frames, pixels, dtype, seed=0, probes=probes)
        mean_ms = per_call_ms(channel_mean_meter, total.mean(1), scene.mean(1), calls)
        rows_ms = per_call_ms(channel_rows_meter, total, scene, calls)
        one_row_ms = per_call_ms(one_row_meter, total, scene, calls)
        package_ms = per_call_ms(physics.metered_exposure, total.mean(1), scene.mean(1), calls)
        luma_gap = (one_row_meter(total, scene) - channel_rows_meter(total, scene)).abs().max()
        mean_gap = (
            (
                physics.metered_exposure(total.mean(1), scene.mean(1))
                - channel_mean_meter(total.mean(1), scene.mean(1))
            )
            .abs()
            .max()
        )
        print(
            f"{label}: session 90's channel mean {mean_ms:.3f} ms, 3912454's luminance {rows_ms:.3f} ms "
            f"({rows_ms / mean_ms:.2f}x), fc04f55's luminance {one_row_ms:.3f} ms ({one_row_ms / mean_ms:.2f}x), "
            f"package's channel mean {package_ms:.3f} ms ({package_ms / mean_ms:.2f}x); largest difference of k: "
            f"fc04f55's from 3912454's {float(luma_gap):.2e}, the package's from session 90's {float(mean_gap):.2e}"
        )


if __name__ == "__main__":
    main()
