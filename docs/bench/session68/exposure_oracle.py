"""camsim's laser blinding with auto-exposure: each pair's exposures, and the library's models fitted with the
laser's gain per pair known exactly.

Per master seed, the case is rendered as the test renders it, recording every capture's exposure (the clean frames,
the laser capture, the attacked frames). In the library's terms the laser's light in pair i is its intensity times
one gain times the clean frame's exposure over the capture's (``clean e / capture e``), a ratio no pair records; the
attacked frame's exposure over the clean one's is the meter's factor ``k``. Then, on the rendered pairs, each model
is fitted on all pairs, by the calibration's 4 inner folds of the fit pairs (the CLI's split and fold seeds; their
RMSE pooled) and on the fit pairs against the held-out ones, twice: with the pairs' intensities as written, and
with each multiplied by its clean frame's exposure over the capture's (the oracle: the per-pair gain known).

Usage: ``PYTHONPATH=. python docs/bench/session68/exposure_oracle.py [--exposures-only] CASE SEED...``
(``--exposures-only``: the exposures, no fits).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.core import kfold, seeded_split
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames

LINEAR_METER = ("linear_light_saturation", "auto_exposure")
MODELS = (
    (),
    ("sensor_gamma",),
    LINEAR_METER,
    (*LINEAR_METER, "sensor_gamma"),
    (*LINEAR_METER, "tone_shoulder"),
    (*LINEAR_METER, "tone_shoulder", "frame_exposure"),
)


def render(name: str, master: int, folder: Path):
    """Write the case's pairs to ``folder``; (case seed, camera, per-pair clean exposure over the capture's, per-pair
    attacked exposure over the clean one's)."""
    import camsim

    _master, _sim, case, seed, rng, camera = next(case_draws(name, [master]))
    exposures = []
    capture = camsim.capture

    def recorded(*args, **kwargs):
        out, exposure = capture(*args, **kwargs)
        exposures.append(exposure)
        return out, exposure

    camsim.capture = recorded
    try:
        pairs = case.render(rng, camera)
    finally:
        camsim.capture = capture
    camsim.write_pairs(folder, pairs)
    # captures in order: clean 0, the laser capture, attacked 0, then clean i and attacked i
    clean = np.array([exposures[0], *exposures[3::2]])
    attacked = np.array([exposures[2], *exposures[4::2]])
    return seed % 2**31, camera, clean / exposures[1], attacked / clean


def scores(problem: BlindingFrames, effects, seed: int) -> str:
    defaults = CalibrateConfig()
    every = np.arange(problem.n_items)
    fit_items, heldout = seeded_split(problem.n_items, defaults.heldout, seed)
    folds = kfold(fit_items, defaults.folds, seed + 1, 2500)
    cv = np.sqrt(np.mean([problem.rmse(problem.fit(effects, train), val) ** 2 for train, val in folds]))
    on_all = problem.fit(effects, every)
    params = {k: round(float(v), 3) for k, v in on_all.params.items()}
    return (
        f"all pairs {problem.rmse(on_all, every):.2f}, inner folds {cv:.2f}, held-out "
        f"{problem.rmse(problem.fit(effects, fit_items), heldout):.2f}; fitted on all {params}"
    )


def main() -> None:
    args = sys.argv[1:]
    exposures_only = args[:1] == ["--exposures-only"]
    args = args[1:] if exposures_only else args
    name, masters = args[0], [int(s) for s in args[1:]]
    defaults = CalibrateConfig()
    for master in masters:
        with tempfile.TemporaryDirectory() as tmp:
            seed, camera, gain_shape, meter = render(name, master, Path(tmp))
            print(f"master {master} {name} (case seed {seed}): tone {camera.tone}")
            print(
                f"  clean e / capture e per pair: {np.round(gain_shape, 3).tolist()} (max/min {gain_shape.max() / gain_shape.min():.2f})"
            )
            print(f"  attacked e / clean e per pair: {np.round(meter, 3).tolist()}")
            if exposures_only:
                continue
            for label, scale in (("as written", None), ("gain per pair known", gain_shape)):
                pairs = load_pairs(Path(tmp), max_side=defaults.max_side)
                if scale is not None:
                    for pair, factor in zip(pairs, scale, strict=True):
                        pair.intensity *= float(factor)
                problem = BlindingFrames(pairs, seed)
                for effects in MODELS:
                    if scale is not None and "frame_exposure" in effects:
                        continue  # the latent the oracle knows
                    print(
                        f"  {label}: {'+'.join(effects) or 'base'}: {scores(problem, frozenset(effects), seed)}",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
