"""How often the nearest-surface-colour test reports structure where the model is right, and how often it finds a
planted hue ripple: colour-triple tables drawn per seed, the true effects fitted on the fit rows (seeded split, 20%
held out), the structure tests on the held-out rows. Two designs: one material (the bottle's: surface colours
within 6 grey levels, 60 rows per projected colour) and many (the stop sign's: surface colours over the whole
range, 12 rows per projected colour), each null (ripple 0) and rippled (0.5, over 30 grey levels of red minus green).

usage: PYTHONPATH=. python docs/bench/session65/neighbour_null.py SEEDS > out.txt
"""

import sys
import tempfile
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.calibration.projection import TRIPLE_COLUMNS, TripleProblem
from lerobot_phantom.calibration.structure import residual_structure

LEVELS = np.array([0.0, 127 / 255, 254 / 255])


def table(seed: int, design: str, ripple: float, path: Path) -> Path:
    rng = np.random.default_rng(seed)
    per_colour = 60 if design == "one_material" else 12
    projected = np.repeat(
        np.stack(np.meshgrid(LEVELS, LEVELS, LEVELS), -1).reshape(-1, 3), per_colour, axis=0
    )
    if design == "one_material":
        surface = rng.uniform(0.25, 0.6, 3) + rng.uniform(-6, 6, projected.shape) / 255
    else:
        surface = rng.uniform(0.05, 0.9, projected.shape)
    hue = 255 * (surface[:, 0] - surface[:, 1])
    strength = 0.4 * (1 + ripple * np.sin(2 * np.pi * hue / 30 + rng.uniform(0, 2 * np.pi)))
    captured = (
        surface + strength[:, None] * projected * (surface + 0.2) + rng.normal(0, 1 / 255, projected.shape)
    )
    data = np.round(np.concatenate([surface, projected, np.clip(captured, 0, 1)], axis=1) * 255).astype(int)
    path.write_text(",".join(TRIPLE_COLUMNS) + "\n" + "\n".join(",".join(map(str, r)) for r in data) + "\n")
    return path


def main() -> None:
    seeds = [int(s) for s in sys.argv[1:]]
    effects = frozenset({"additive_light", "albedo_modulation"})
    with tempfile.TemporaryDirectory() as tmp:
        for design in ("one_material", "many_materials"):
            for ripple in (0.0, 0.5):
                reported, values = 0, []
                for seed in seeds:
                    problem = TripleProblem(table(seed, design, ripple, Path(tmp) / "t.csv"))
                    fit_items, heldout = seeded_split(problem.n_items, 0.2, seed)
                    fit = problem.fit(effects, fit_items)
                    result = residual_structure(
                        problem,
                        fit,
                        heldout,
                        base_mse=1.0,
                        rng=np.random.default_rng(seed),
                        fit_items=fit_items,
                    )
                    test = next(t for t in result["tests"] if t["variable"] == "nearest_surface_colour")
                    reported += test["significant"]
                    values.append(test["value"])
                    others = [t["variable"] for t in result["tests"] if t["significant"] and t is not test]
                    print(
                        f"{design} ripple {ripple} seed {seed}: correlation {test['value']:+.3f} "
                        f"[{test['interval']['low']:+.3f}, {test['interval']['high']:+.3f}] "
                        f"reported {test['significant']}; other tests reporting: {others}",
                        flush=True,
                    )
                print(
                    f"== {design} ripple {ripple}: reported on {reported} of {len(seeds)}; correlation "
                    f"{np.min(values):+.3f} to {np.max(values):+.3f}, median {np.median(values):+.3f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
