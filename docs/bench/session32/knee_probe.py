"""Why the filmic ``projection_crosstalk`` fits pin the shoulder's knee at its bound: in-sample fits of the case's
full planted form (additive light + shoulder + cross-talk + reflectance) on all of a case's pairs, the emitted
pattern's light taken four ways:

* ``camera curve``: decoded by the fitted camera curve, as the library does;
* ``camera curve, knee fixed``: the same with the shoulder fixed at the closest fit of the library's form to
  camsim's filmic curve (shoulder 38.8, exponent 1.19: ``camsim_session15/filmic_shoulder_fit.txt``);
* ``pattern ** 2.2``: the frame through camsim's projector display gamma (2.2), the shoulder free;
* ``pattern ** pg``: the same with the projector gamma fitted too.

Prints the RMSE (grey levels), the reflectance floor (0: full modulation, as planted; 2: none) and the knee.
Usage: ``PYTHONPATH=. python docs/bench/session32/knee_probe.py PAIRS_DIR...`` from the repository root, where
PAIRS_DIR is ``ROOT/projection_crosstalk/pairs`` as ``session31/camsim_case_variants.py`` wrote it.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.core import Param, fit_least_squares
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.light_projection import ProjectionFrames
from lerobot_phantom.calibration.projection import projection_predict, projection_specs

EFFECTS = frozenset({"additive_light", "tone_shoulder", "channel_crosstalk", "albedo_modulation"})
CLOSEST_KNEE = {"shoulder": 38.8, "shoulder_exponent": 1.19}
PROJECTOR_GAMMA = Param("projector_gamma", 2.2, 1.0, 3.5, scale=0.5)


def probe(folder: Path) -> None:
    problem = ProjectionFrames(load_pairs(folder, max_side=256), seed=0)
    items = np.arange(problem.n_items)
    rows = [problem.features(int(i), problem.samples[int(i)]) for i in items]
    feats = {k: torch.cat([r[k] for r in rows]) for k in rows[0]}
    target = torch.cat(
        [problem.pairs[int(i)].attacked.reshape(3, -1)[:, problem.samples[int(i)]].T for i in items]
    )
    specs = projection_specs(EFFECTS)
    free_knee = [s for s in specs if s.name not in CLOSEST_KNEE]
    diagonal = {f"crosstalk_{i}{i}": 0.3 for i in range(3)}

    def fit(label: str, params: list[Param], fixed: dict, projector: bool) -> None:
        def residuals(p):
            p = {**fixed, **p}
            light = (
                feats["projected"].clamp(min=1e-12) ** p.get("projector_gamma", 2.2) if projector else None
            )
            predicted = projection_predict(
                feats["surface"], feats["projected"], feats["strength"], EFFECTS, p, projected_light=light
            )
            return (predicted - target).ravel()

        found = fit_least_squares(params, residuals, warm=diagonal, starts=[{**CLOSEST_KNEE, **diagonal}])
        rmse = 255 * float(residuals({k: torch.tensor(v) for k, v in found.items()}).pow(2).mean().sqrt())
        shown = {k: round(v, 3) for k, v in {**fixed, **found}.items() if not k.startswith("crosstalk")}
        print(f"  {label}: RMSE {rmse:.3f}, {shown}")

    print(folder)
    fit("camera curve", specs, {}, projector=False)
    fit("camera curve, knee fixed", free_knee, CLOSEST_KNEE, projector=False)
    fit("pattern ** 2.2", specs, {}, projector=True)
    fit("pattern ** pg", [*specs, PROJECTOR_GAMMA], {}, projector=True)


if __name__ == "__main__":
    for path in sys.argv[1:]:
        probe(Path(path))
