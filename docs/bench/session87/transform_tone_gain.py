"""What the attack transforms gain from taking a fitted shoulder itself rather than its closest power law.

Until session 87 ``transform_kwargs`` handed an attack the power law closest to a fitted ``tone_shoulder``
(``tone.equivalent_power_gamma``); now the attack takes the curve (``shoulder_kwargs``, ``physics.ShoulderCurve``).
On each input, held-out items, RMSE in grey levels against what the camera recorded, of: the calibration model's
own prediction (the floor the transform can reach), the transform with the shoulder, the transform with the power
law it was given before.

- ``--stop-sign CSV``: SLAP's stop sign colour triples (``../shared/measured/projection/slap_stop_sign_triples.csv``,
  not in this repository), calibrated as the CLI does (seed 0, 20% held out); the transform's light model
  (``LightProjection(**kwargs).project``, what the transform applies) on the
  held-out rows.
- ``CASE:CASE_SEED``: camsim blur draws (tests/calibration/test_independent_sim.py), fitted as the resonance in a
  shouldered curve on the CLI's fit pairs (as the suite's filmic blur test does); ``UltrasoundBlur`` applied to
  each held-out clean frame with the fitted displacement at that frame's intensity.
- ``CASE:CASE_SEED`` of a laser strip case (``strip_*``): the rolling-shutter stripe in a shouldered curve (with
  ``stripe_period`` for ``strip_period``) fitted on the fit pairs; ``LaserColorStrip`` applied to each held-out
  clean frame at its intensity and at the pulse phase registered on that frame (the phase no one knows in advance:
  the model's figure is the registered one too, ``predict_registered``).

Usage: ``CAMSIM_SEED=0 PYTHONPATH=.:tests/calibration:tests python docs/bench/session87/transform_tone_gain.py
[--stop-sign CSV] CASE:CASE_SEED...`` (blur and laser strip cases)
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem, calibrate
from lerobot_phantom.calibration.core import Fit, seeded_split
from lerobot_phantom.calibration.identify import error_ratio
from lerobot_phantom.calibration.tone import equivalent_power_gamma
from lerobot_phantom.transforms.laser_color_strip import LaserColorStrip
from lerobot_phantom.transforms.light_projection import LightProjection
from lerobot_phantom.transforms.ultrasound_blur import UltrasoundBlur

RESONANCE = frozenset({"sinusoidal_motion", "tone_shoulder"})
STRIPE = {"exposure_overlap", "tone_shoulder"}


def rmse(errors: list[torch.Tensor]) -> float:
    return float(255.0 * torch.cat([e.ravel() for e in errors]).pow(2).mean().sqrt())


def as_power_law(kwargs: dict, params: dict, gamma=None) -> dict:
    """The options as ``transform_kwargs`` gave them before session 87: the closest power law, no shoulder."""
    old = {k: v for k, v in kwargs.items() if k not in ("shoulder", "shoulder_exponent")}
    old["gamma"] = equivalent_power_gamma(params, gamma)
    return old


def stop_sign(csv: Path) -> None:
    with tempfile.TemporaryDirectory() as folder:
        cfg = CalibrateConfig(attack="light_projection", measured=str(csv), out=str(Path(folder) / "out"))
        report = calibrate(cfg)
    fit = Fit(frozenset(report["extended"]["effects"]), report["extended"]["params"])
    problem = build_problem(cfg)
    _, heldout = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
    index = torch.as_tensor(heldout)
    target = problem.captured[index]
    # the rows as a one-column image: (1, 3, N, 1)
    surface, projected = (t[index].T.reshape(1, 3, -1, 1) for t in (problem.surface, problem.projected))
    kwargs = problem.transform_kwargs(fit)

    def transformed(options: dict) -> torch.Tensor:
        # the table's rows are all at the attack's full strength (TripleProblem.strength is 1)
        light = LightProjection(**options).project(surface, projected, torch.ones(1, dtype=torch.float64))
        return light.reshape(3, -1).T

    model = problem.predict(fit.effects, fit.params, heldout)
    shouldered = transformed(kwargs)
    power_law = transformed(as_power_law(kwargs, fit.params, kwargs["gamma"]))
    # paired over the held-out rows, as the report's gain (the report's own seed stream is not reused)
    ratio = error_ratio(
        (255 * (power_law - target)).pow(2).sum(1).numpy(),
        (255 * (shouldered - target)).pow(2).sum(1).numpy(),
        rng=np.random.default_rng(87),
    )
    print(
        f"stop sign ({csv.name}), {len(heldout)} held-out rows, named {sorted(fit.effects)}, shoulder "
        f"{fit.params['shoulder']:.3f} exponent {fit.params['shoulder_exponent']:.3f} (closest power law "
        f"{equivalent_power_gamma(fit.params, kwargs['gamma']):.2f}): model {rmse([model - target]):.2f}, "
        f"transform with the shoulder {rmse([shouldered - target]):.2f}, with the power law "
        f"{rmse([power_law - target]):.2f} (ratio {ratio.estimate:.3f}, 90% paired bootstrap over rows "
        f"{ratio.low:.3f}-{ratio.high:.3f}); the transform with the shoulder against the model: largest "
        f"{255 * float((shouldered - model).abs().max()):.2e} grey levels",
        flush=True,
    )


def blur_attack(attack, problem, fit, index: int) -> torch.Tensor:
    from calibration_testkit import blurred_by_the_attack

    return blurred_by_the_attack(attack, problem, fit, index)


def strip_attack(attack, problem, fit, index: int) -> torch.Tensor:
    pair = problem.pairs[index]
    params = attack.sample_params(
        1, pair.height, pair.width, intensity=torch.tensor([pair.intensity], dtype=torch.float64)
    )
    # at the pulse phase registered on the pair; the transform's row time is the frame time over its rows
    params["phase_s"] = torch.tensor(
        [problem.best_phase(fit.params, index) / pair.height], dtype=torch.float64
    )
    return attack.apply_params(pair.clean.unsqueeze(0), params)[0]


# per camsim attack: the attack transform, the effects fitted (beside the case's own period) and its frame
DRAWS = {
    "blur": (UltrasoundBlur, RESONANCE, blur_attack),
    "strip": (LaserColorStrip, STRIPE, strip_attack),
}


def camsim_draw(name: str, case_seed: int) -> None:
    import test_independent_sim as sim

    kind = "strip" if name.startswith("strip_") else "blur"
    attack_class, effects, attacked = DRAWS[kind]
    effects = frozenset(effects | ({"stripe_period"} if name == "strip_period" else set()))
    with tempfile.TemporaryDirectory() as folder:
        problem, fit_items, heldout = sim.drawn_split(name, case_seed, Path(folder))
        camera = sim.case_camera(sim.CASE_BY_NAME[name], case_seed)[2]
        fit = problem.fit(effects, fit_items)
    kwargs = problem.transform_kwargs(fit)
    attacks = {
        "shoulder": attack_class(**kwargs),
        "power law": attack_class(**as_power_law(kwargs, fit.params)),
    }
    errors: dict[str, list[torch.Tensor]] = {"model": [], **{k: [] for k in attacks}}
    for i in heldout:
        pair = problem.pairs[int(i)]
        # a stripe's prediction is the registered one (LatentFrameProblem.predict_pair), at the attack's phase
        errors["model"].append(problem.predict_pair(fit, int(i)) - pair.attacked)
        for what, attack in attacks.items():
            errors[what].append(attacked(attack, problem, fit, int(i)) - pair.attacked)
    print(
        f"{name} case seed {case_seed} ({camera.tone}), {len(heldout)} held-out pairs, {sorted(effects)}, shoulder "
        f"{fit.params['shoulder']:.3f} exponent {fit.params['shoulder_exponent']:.3f} (closest power law "
        f"{equivalent_power_gamma(fit.params):.2f}): model {rmse(errors['model']):.2f}, transform with the "
        f"shoulder {rmse(errors['shoulder']):.2f}, with the power law {rmse(errors['power law']):.2f}",
        flush=True,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop-sign", type=Path)
    parser.add_argument("draws", nargs="*", help="CASE:CASE_SEED")
    args = parser.parse_args()
    torch.set_num_threads(1)
    if args.stop_sign is not None:
        stop_sign(args.stop_sign)
    for draw in args.draws:
        name, seed = draw.split(":")
        camsim_draw(name, int(seed))


if __name__ == "__main__":
    main()
