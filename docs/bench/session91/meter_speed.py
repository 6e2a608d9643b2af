"""The auto-exposure meter's cost, one run: ``physics.metered_exposure`` as each commit wrote it, read from git (no
copies): cca201a's (session 90: the channel mean, ``(n, P)`` one level per pixel, 12 Newton steps), 3912454's (the
luminance of the clipped channels on ``(n, 3, P)``, read channel by channel, as the calibration passed it: a
transposed view of its ``(n * P, 3)`` probes), fc04f55's (a frame's channels in one row, stopped once Newton's steps
move ``k`` by rounding only) and the working tree's (after session 91's revert the channel mean again, with that
stop), on the calibration's shape (8 frames of ``METER_PROBES`` pixels, float64, one thread) and on an attack's (a
batch of 8 224x224 frames, float32, contiguous). Prints each one's time per call, its ratio to cca201a's, and the
largest difference of fc04f55's exposures from 3912454's and of the working tree's from cca201a's.
(``meter_speed_fc04f55.txt`` is this script as at aa0747b, whose "package" was fc04f55's luminance meter and whose
older meters were copies; ``meter_speed_836ec3f.txt`` as at 0a7fe48.)

Usage: ``PYTHONPATH=. python docs/bench/session91/meter_speed.py`` from the repository (git must hold the commits).
"""

from __future__ import annotations

import subprocess
import sys
import time
import types

import torch

from lerobot_phantom.calibration.frame_models.laser_blinding import METER_PROBES
from lerobot_phantom.transforms import physics

PHYSICS = "lerobot_phantom/transforms/physics.py"


def meter_at(commit: str):
    """``physics.metered_exposure`` as ``commit`` wrote it (the module executed from git, torch its only import)."""
    source = subprocess.run(
        ["git", "show", f"{commit}:{PHYSICS}"], capture_output=True, text=True, check=True
    )
    module = types.ModuleType(f"physics_{commit}")
    sys.modules[module.__name__] = module  # its dataclasses look their module up
    exec(compile(source.stdout, f"{commit}:{PHYSICS}", "exec"), module.__dict__)
    return module.metered_exposure


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
    session90, rows, one_row = meter_at("cca201a"), meter_at("3912454"), meter_at("fc04f55")
    for label, frames, pixels, dtype, calls, probes in (
        ("calibration, 8 x METER_PROBES float64", 8, METER_PROBES, torch.float64, 300, True),
        ("attack, 8 x 224 x 224 float32", 8, 224 * 224, torch.float32, 10, False),
    ):
        total, scene = light(frames, pixels, dtype, seed=0, probes=probes)
        means = total.mean(1), scene.mean(1)
        mean_ms = per_call_ms(session90, *means, calls)
        rows_ms = per_call_ms(rows, total, scene, calls)
        one_row_ms = per_call_ms(one_row, total, scene, calls)
        tree_ms = per_call_ms(physics.metered_exposure, *means, calls)
        luma_gap = (one_row(total, scene) - rows(total, scene)).abs().max()
        mean_gap = (physics.metered_exposure(*means) - session90(*means)).abs().max()
        print(
            f"{label}: cca201a's channel mean {mean_ms:.3f} ms, 3912454's luminance {rows_ms:.3f} ms "
            f"({rows_ms / mean_ms:.2f}x), fc04f55's luminance {one_row_ms:.3f} ms ({one_row_ms / mean_ms:.2f}x), "
            f"working tree's channel mean {tree_ms:.3f} ms ({tree_ms / mean_ms:.2f}x); largest difference of k: "
            f"fc04f55's from 3912454's {float(luma_gap):.2e}, the working tree's from cca201a's {float(mean_gap):.2e}"
        )


if __name__ == "__main__":
    main()
