"""camsim's light projection cases on a colour-correcting camera (``CAMSIM_CCM=1``): one effect set fitted on the
fit pairs four ways, fit and held-out RMSE (grey levels) of each. The set is the case's planted effects with the
camera's tone form (a shoulder on filmic cameras, a gamma on the others) and ``light_spread`` for an emitted pattern:

- ``stored``: as the package composed light before session 97, in the stored (colour-corrected) channels;
- ``raw, camsim's matrix``: ``colour_correction`` with camsim's own matrix in place of the fitted one (an oracle);
- ``raw, fitted matrix``: ``colour_correction`` as the package fits it (one take per raw channel);
- ``raw, six off-diagonals``: the matrix's six off-diagonals fitted free (rows summing to 1).

Further effect sets given after the seed (names joined by ``+``, one master seed then) are scored without and with
``colour_correction`` as the package fits it.

Usage: ``CAMSIM_CCM=1 PYTHONPATH=.:tests/calibration:tests python docs/bench/session97/ccm_projection_forms.py CASE
MASTER_SEED... [SET...]``"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration import projection
from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem
from lerobot_phantom.calibration.core import Param, cross_validated, seeded_split, selection_folds

OFF_DIAGONALS = tuple(f"ccm_{i}{j}" for i in range(3) for j in range(3) if i != j)
fitted_matrix, package_specs = projection.correction_matrix, projection.projection_specs


def six_off_diagonals(params: dict) -> torch.Tensor:
    off = torch.zeros(3, 3, dtype=torch.float64)
    for name in OFF_DIAGONALS:
        off[int(name[-2]), int(name[-1])] = torch.as_tensor(params[name], dtype=torch.float64)
    return off + torch.diag(1.0 - off.sum(1))


def six_specs(effects, pattern_record):
    specs = [s for s in package_specs(effects, pattern_record) if not s.name.startswith("ccm_")]
    return (
        specs + [Param(n, -0.1, -1.0, 0.0, scale=0.1) for n in OFF_DIAGONALS]
        if "colour_correction" in effects
        else specs
    )


def main() -> None:
    import camsim

    name = sys.argv[1]
    seeds = [int(s) for s in sys.argv[2:] if s.isdigit()]
    extra = [frozenset(s.split("+")) for s in sys.argv[2:] if not s.isdigit()]
    for master, _sim, case, seed, rng, camera in case_draws(name, seeds):
        with tempfile.TemporaryDirectory() as folder:
            camsim.write_pairs(Path(folder), case.render(rng, camera))
            config = CalibrateConfig(
                attack=case.attack, measured=folder, out=f"{folder}/out", seed=seed % 2**31
            )
            problem = build_problem(config)
            fit_items, heldout = seeded_split(problem.n_items, config.heldout, config.seed)
            tone = "tone_shoulder" if camera.tone == "filmic" else "sensor_gamma"
            spread = {"light_spread"} if problem.pattern_record == "emitted" else set()
            planted = frozenset(case.planted | {tone} | spread)
            true_matrix = torch.tensor(np.reshape(camera.ccm, (3, 3)), dtype=torch.float64)
            print(
                f"{master} {name} (case seed {seed}, {camera.tone} camera, {'+'.join(sorted(planted))}); "
                f"camsim's matrix {np.round(camera.ccm, 3).tolist()}",
                flush=True,
            )
            forms = (
                ("stored", planted, fitted_matrix, package_specs),
                (
                    "raw, camsim's matrix",
                    planted | {"colour_correction"},
                    lambda p, m=true_matrix: m,
                    package_specs,
                ),
                ("raw, fitted matrix", planted | {"colour_correction"}, fitted_matrix, package_specs),
                ("raw, six off-diagonals", planted | {"colour_correction"}, six_off_diagonals, six_specs),
            )
            for effects in extra:
                forms += (
                    ("given set", effects, fitted_matrix, package_specs),
                    (
                        "given set, raw, fitted matrix",
                        effects | {"colour_correction"},
                        fitted_matrix,
                        package_specs,
                    ),
                )
            splits = selection_folds(fit_items, 4, config.seed, 2500)
            for label, effects, matrix, specs in forms:
                projection.correction_matrix, projection.projection_specs = matrix, specs
                score = cross_validated(problem, frozenset(effects), splits, None)[0]
                fit = problem.fit(frozenset(effects), fit_items)
                shown = {k: round(v, 3) for k, v in fit.params.items() if not k.startswith("crosstalk")}
                print(
                    f"  {label} ({'+'.join(sorted(effects))}): cross-validated {score:.2f}, "
                    f"fit {problem.rmse(fit, fit_items):.2f}, held-out {problem.rmse(fit, heldout):.2f}; {shown}",
                    flush=True,
                )
            projection.correction_matrix, projection.projection_specs = fitted_matrix, package_specs


if __name__ == "__main__":
    main()
