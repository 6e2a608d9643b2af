"""Golden outputs: every camera attack, seeds {0, 1} x shapes {(3, 17, 23), (2, 3, 32, 32)} at a random intensity.

The files in ``golden/`` pin today's behaviour so that any change to an attack's output (a refactor, a new torch)
shows up as a failing test. A deliberate change of an attack regenerates them:

    PHANTOM_REGENERATE_GOLDEN=1 python -m pytest tests/transforms/test_golden.py

(the regenerating run writes the files and skips; commit them with the change that explains why they moved).
Comparisons allow one grey level on at most 1 % of the values: float rounding at exact .5 boundaries may differ
between CPUs / SIMD paths, a real change of the algorithm moves far more.
"""

import os
from pathlib import Path

import pytest
import torch

from lerobot_phantom.transforms.registry import CAMERA_ATTACKS, make_attack

os.environ.setdefault("HF_HUB_OFFLINE", "1")

GOLDEN_DIR = Path(__file__).parent / "golden"
REGENERATE = os.environ.get("PHANTOM_REGENERATE_GOLDEN", "") == "1"
SEEDS = (0, 1)
SHAPES = ((3, 17, 23), (2, 3, 32, 32))


def _input(seed: int, shape: tuple[int, ...]) -> torch.Tensor:
    generator = torch.Generator().manual_seed(1000 + seed)
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=generator)


def _cases(name: str) -> list[dict]:
    cases = []
    for seed in SEEDS:
        for shape in SHAPES:
            image = _input(seed, shape)
            attack = make_attack(name, intensity="random", seed=seed)
            batch = 1 if len(shape) == 3 else shape[0]
            params = attack.make_params([image])
            assert params["intensity"].shape == (batch,)
            cases.append(
                {
                    "seed": seed,
                    "shape": shape,
                    "input_sum": image.long().sum(),
                    "intensity": params["intensity"],
                    "output": attack.apply_params(image, params),
                    "output_float": attack.apply_params(image.float() / 255, params),
                }
            )
    return cases


def _assert_close_grey(actual: torch.Tensor, expected: torch.Tensor, what: str) -> None:
    assert actual.shape == expected.shape, what
    diff = (actual.double() - expected.double()).abs() * (255.0 if actual.is_floating_point() else 1.0)
    assert float(diff.max()) <= 1.0 + 1e-6, f"{what}: max difference {float(diff.max()):.2f} grey levels"
    assert float((diff > 0.5).double().mean()) <= 0.01, (
        f"{what}: {float((diff > 0.5).double().mean()):.2%} differ"
    )


@pytest.mark.parametrize("name", CAMERA_ATTACKS)
def test_golden_outputs(name):
    path = GOLDEN_DIR / f"{name}.pt"
    cases = _cases(name)
    if REGENERATE:
        GOLDEN_DIR.mkdir(exist_ok=True)
        stored = [{k: v for k, v in case.items() if k != "output_float"} for case in cases]
        torch.save(stored, path)
        pytest.skip(f"regenerated {path.name}")
    if not path.exists():
        pytest.fail(f"missing golden file {path}; regenerate with PHANTOM_REGENERATE_GOLDEN=1")
    golden = torch.load(path, weights_only=True)
    assert len(golden) == len(cases)
    for case, expected in zip(cases, golden, strict=True):
        what = f"{name} seed={case['seed']} shape={case['shape']}"
        assert tuple(expected["shape"]) == case["shape"], what
        assert int(expected["input_sum"]) == int(case["input_sum"]), f"{what}: the input generator changed"
        torch.testing.assert_close(case["intensity"], expected["intensity"], msg=f"{what}: intensity draw")
        _assert_close_grey(case["output"], expected["output"], what)
        # the float path is the stored uint8 result before its final rounding (half a grey level)
        rounding = (case["output_float"].double() * 255 - expected["output"].double()).abs().max()
        assert float(rounding) <= 0.5 + 1e-3, f"{what} (float input): {float(rounding):.3f} grey levels off"
        identity = torch.equal(expected["output"], _input(case["seed"], case["shape"]))
        assert not identity, f"{what}: golden output is the identity"
