"""``physics.line_blur`` of two checkouts: equal outputs or not, gradients, one-thread timings.

python line_blur_check.py BEFORE/lerobot_phantom/transforms/physics.py AFTER/lerobot_phantom/transforms/physics.py
"""

import importlib.util
import sys
import timeit

import torch


def load(path: str, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main() -> None:
    torch.set_num_threads(1)
    before, after = load(sys.argv[1], "before_physics"), load(sys.argv[2], "after_physics")
    generator = torch.Generator().manual_seed(0)
    compared = mismatched = 0
    for dtype in (torch.float32, torch.float64):
        for batch, height, width in [(1, 1, 1), (1, 1, 7), (2, 5, 1), (1, 48, 64), (3, 64, 80), (1, 71, 83)]:
            for path in ("uniform", "sinusoidal"):
                x = torch.rand(batch, 3, height, width, generator=generator, dtype=dtype)
                dx = torch.randn(batch, generator=generator, dtype=dtype) * 6
                dy = torch.randn(batch, generator=generator, dtype=dtype) * 6
                taps = before.blur_taps(float(dx.abs().max()), float(dy.abs().max()))
                offsets = before.blur_path_offsets(path, taps, dtype=dtype)
                # per-sample tensors, Python numbers, 0-dim tensors
                for shift_x, shift_y in [(dx, dy), (float(dx[0]), float(dy[0])), (dx[0], dy[0])]:
                    compared += 1
                    mismatched += not torch.equal(
                        before.line_blur(x, shift_x, shift_y, offsets),
                        after.line_blur(x, shift_x, shift_y, offsets),
                    )
    print(f"outputs: {mismatched} of {compared} cases differ in any bit")
    largest = 0.0
    for _ in range(20):
        x = torch.rand(1, 3, 20, 30, generator=generator, dtype=torch.float64)
        offsets = before.blur_path_offsets("sinusoidal", 7, dtype=torch.float64)
        grads = []
        for module in (before, after):
            dx = torch.tensor(2.5, dtype=torch.float64, requires_grad=True)
            grads.append(torch.autograd.grad(module.line_blur(x, dx, 1.0, offsets).sum(), dx)[0])
        largest = max(largest, float((grads[0] - grads[1]).abs() / grads[0].abs()))
    print(f"d/d(dx) over 20 frames: largest relative difference {largest:.2g}")
    for height, width in [(64, 80), (71, 83), (96, 128)]:
        x = torch.rand(1, 3, height, width, generator=generator, dtype=torch.float64)
        offsets = before.blur_path_offsets("sinusoidal", 9, dtype=torch.float64)
        dx, dy = torch.tensor(3.0, dtype=torch.float64), torch.tensor(1.5, dtype=torch.float64)
        best = [
            min(
                timeit.repeat(
                    lambda m=m, x=x, dx=dx, dy=dy, o=offsets: m.line_blur(x, dx, dy, o), number=50, repeat=5
                )
            )
            / 50
            for m in (before, after)
        ]
        print(
            f"{height}x{width}, 9 taps: {best[0] * 1e3:.2f} -> {best[1] * 1e3:.2f} ms ({best[0] / best[1]:.2f}x)"
        )


if __name__ == "__main__":
    main()
