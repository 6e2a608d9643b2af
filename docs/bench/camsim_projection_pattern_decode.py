"""How much the reflectance term can pay on camsim's cross-talk case under a filmic camera, with the pattern decoded
the way camsim's projector emits it.

Usage: ``PYTHONPATH=. python docs/bench/camsim_projection_pattern_decode.py TESTS_DIR CASE DECODE SEED...``
(TESTS_DIR holds ``test_independent_sim.py`` and ``camsim.py``; CASE e.g. ``projection_crosstalk``; DECODE ``camera``
for the library's decoding of the pattern through the fitted tone curve, ``projector`` for ``pattern ** 2.2``, the
light camsim's projector makes of an emitted frame). Renders the case as the test does and fits, in-sample on all
pairs (the package's pixel sample), the case's model with ``tone_shoulder`` or ``sensor_gamma``, without and with
``albedo_modulation``. Prints the RMSE in grey levels over all pixels, over the pixels the pattern lights and over
the others, and the reflectance floor (0: full modulation, 2: the end of its range).
"""

from __future__ import annotations

import importlib
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration import projection
from lerobot_phantom.calibration.core import fit_least_squares
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames

PROJECTOR_GAMMA = 2.2  # camsim: projector light = frame ** 2.2


def rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(values**2)))


def report_case(camsim, sim, name: str, decode: str, master: int) -> None:
    base = ("additive_light", "channel_crosstalk") if name == "projection_crosstalk" else ("additive_light",)
    case = sim.CASE_BY_NAME[name]
    seed, rng, camera = sim.case_camera(case)
    with tempfile.TemporaryDirectory() as scratch:
        camsim.write_pairs(Path(scratch) / "pairs", case.render(rng, camera))
        pairs = load_pairs(Path(scratch) / "pairs", max_side=256)
    problem = ProjectionFrames(pairs, seed=0)
    feats = [problem.features(i, problem.samples[i]) for i in range(len(pairs))]
    stacked = {k: torch.cat([f[k] for f in feats]) for k in feats[0]}
    target = torch.cat(
        [p.attacked.reshape(3, -1)[:, s].T for p, s in zip(pairs, problem.samples, strict=True)]
    )
    lit = (stacked["projected"].amax(1) > 0).numpy()

    def predict(effects, params):
        pattern = stacked["projected"]
        if decode == "projector":  # re-encode the projector's light so the model's own decoding returns it
            _, encode = projection.tone_curve(effects, params)
            pattern = encode(pattern.clamp(min=0) ** PROJECTOR_GAMMA)
        return projection.projection_predict(
            stacked["surface"], pattern, stacked["strength"], effects, params
        )

    print(
        f"master {master} case seed {seed}: tone {camera.tone}, lit share {lit.mean():.2f}, pattern {decode}"
    )
    for tone in ("tone_shoulder", "sensor_gamma"):
        rows = []
        for extra in ((), ("albedo_modulation",)):
            effects = frozenset((*base, tone, *extra))
            params = fit_least_squares(
                projection.projection_specs(effects), lambda p, e=effects: (predict(e, p) - target).ravel()
            )
            with torch.no_grad():
                tensors = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
                residual = 255 * (predict(effects, tensors) - target).numpy()
            rows.append((rms(residual), rms(residual[lit]), rms(residual[~lit]), params))
        (a0, l0, u0, _), (a1, l1, u1, p1) = rows
        print(
            f"  {tone}: all {a0:.2f} -> {a1:.2f} ({1 - a1 / a0:.1%}), lit {l0:.2f} -> {l1:.2f} "
            f"({1 - l1 / l0:.1%}), unlit {u0:.2f} -> {u1:.2f}; with reflectance: floor "
            f"{p1['reflectance_floor']:.2f}"
        )


def main() -> None:
    tests_dir, name, decode, seeds = sys.argv[1], sys.argv[2], sys.argv[3], [int(s) for s in sys.argv[4:]]
    if decode not in ("camera", "projector"):
        raise SystemExit(f"DECODE must be camera or projector, got {decode!r}")
    sys.path.insert(0, tests_dir)
    sys.path.insert(1, str(Path(tests_dir).parent))  # tests/sampling.py, which the case selection imports
    camsim = importlib.import_module("camsim")
    for master in seeds:
        os.environ["CAMSIM_SEED"] = str(master)
        sim = importlib.reload(importlib.import_module("test_independent_sim"))
        report_case(camsim, sim, name, decode, master)


if __name__ == "__main__":
    main()
