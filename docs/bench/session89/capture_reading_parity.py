"""The laser blinding frame model's capture readings (beam profile, where it was measured, dark field, saturated core
depth and radius, each pixel's distance from the spot, the dark level's distance; its ``features``) on camsim
blinding draws, written by one package and compared with another's: session 89
moved the reading from scipy (``calibration/frame_models/laser_blinding.py``) to torch (``transforms/capture.py``).

Usage (from the repository root; CAMSIM_SEED only satisfies test_independent_sim's import)::

    CAMSIM_SEED=0 PYTHONPATH=TREE:tests/calibration:tests python docs/bench/session89/capture_reading_parity.py \
        dump OUT.pt WORKDIR
    python docs/bench/session89/capture_reading_parity.py compare OLD.pt NEW.pt
"""

from __future__ import annotations

import sys
from pathlib import Path

import torch

# session 88's six draws (docs/bench/session88/blinding_attack_*.txt), then one fixed seed per blinding case
DRAWS = [
    ("blinding_halo", 2074608951),
    ("blinding_auto_exposure", 1758681884),
    ("blinding_saturation", 1688866427),
    ("blinding_halo", 2573805010),
    ("blinding_auto_exposure", 37305684),
    ("blinding_null", 3027201163),
]


def dump(out: Path, workdir: Path) -> None:
    import test_independent_sim as sim

    cases = [name for name in sim.CASE_BY_NAME if name.startswith("blinding")]
    readings = {}
    for case, seed in DRAWS + [(name, 12345 + k) for k, name in enumerate(cases)]:
        folder = workdir / f"{case}_{seed}"
        folder.mkdir(parents=True, exist_ok=True)
        problem, _, _ = sim.drawn_split(case, seed, folder)
        # the frame model's inputs from its captures, read through its public features (any package's)
        names = ("beam", "unmeasured", "dark", "core_depth", "core_radius", "radius", "dark_radius")
        features = [problem.features(i, None) for i in range(len(problem.pairs))]
        readings[f"{case}:{seed}"] = {name: [f[name] for f in features] for name in names}
    torch.save(readings, out)
    print(
        f"{len(readings)} draws, {sum(len(r['beam']) for r in readings.values())} captures: {list(readings)}"
    )


def compare(old: Path, new: Path) -> None:
    a, b = torch.load(old, weights_only=False), torch.load(new, weights_only=False)
    assert a.keys() == b.keys()
    worst: dict[str, float] = {}
    for draw in a:
        for name in a[draw]:
            for x, y in zip(a[draw][name], b[draw][name], strict=True):
                worst[name] = max(worst.get(name, 0.0), float((x.double() - y.double()).abs().max()))
    captures = sum(len(r["beam"]) for r in a.values())
    print(f"{len(a)} draws, {captures} captures; largest difference per reading: {worst}")


if __name__ == "__main__":
    if sys.argv[1] == "dump":
        dump(Path(sys.argv[2]), Path(sys.argv[3]))
    else:
        compare(Path(sys.argv[2]), Path(sys.argv[3]))
