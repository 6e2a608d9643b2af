"""Why does a matrix take of laser blinding's ``colour_correction`` run to its bound 1 on camsim's colour-correcting
cameras? Fits one rendered case's pairs (all of them) with the package's model and with one stated change, and
prints the fitted takes, the RMSE over all pairs (or over the pixels whose clean frame stores no channel at 0) and,
with ``--zones``, the mean squared error per channel by distance from the capture's brightest point.

Changes (each a monkeypatch of the package's model, nothing else): ``--takes true`` holds each ``ccm_<channel>`` at
its column's mean of camsim's true off-diagonals; ``--form split`` gives the laser's column a take into each other
channel, ``--form six`` every off-diagonal its own; ``--pixels unclipped`` fits and scores only pixels whose clean
frame stores every channel above 2.5/255 (their raw scene is known through the matrix's inverse); ``--core faint``
reads the beam inside the capture's saturated laser channel from a fainter channel the capture measured there
unsaturated (stored_c = M[c,L] + (M[c,c] col_c + M[c,k] col_k) B), instead of the Gaussian continuation alone;
``--high H`` widens the takes' range to [0, H]; ``--meter luma`` has the auto-exposure meter read Rec. 709 luminance
of the composed light (``LUMA``; camsim's meter reads luminance, centre-weighted) instead of its three channels'
mean, the package's meter (``luminance_meter_attempt.patch`` made that the package's form; reverted).

Usage: ``CAMSIM_CCM=1 PYTHONPATH=. python docs/bench/session71/ccm_take_probe.py CASE PAIRS_DIR MASTER_SEED GROUP[,GROUP]
[--takes free|true] [--form column|split|six] [--pixels all|unclipped] [--core package|faint] [--high H]
[--meter mean|luma] [--zones]``
(PAIRS_DIR: a case's ``pairs`` folder as ``session64/run_camsim_case.py`` or ``ccm_take_variants.py`` wrote it; the
camera's true matrix is drawn again from MASTER_SEED)."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(1, "tests/calibration")
sys.path.insert(2, "tests")
from camsim_case_cameras import case_draws

from lerobot_phantom.calibration.frame_models import laser_blinding as lb
from lerobot_phantom.calibration.frame_models.common import load_pairs

LUMA = (0.2126, 0.7152, 0.0722)  # Rec. 709 luminance weights


def take_names(form: str, laser: int) -> dict[tuple[int, int], str]:
    """(into channel i, of channel j) -> the parameter taking channel j's raw light out of channel i."""
    names = {}
    for j, c in enumerate(lb.CHANNELS):
        for i in range(3):
            if i != j:
                split = form == "six" or (form == "split" and j == laser)
                names[(i, j)] = f"ccm_{c}_to_{lb.CHANNELS[i]}" if split else f"ccm_{c}"
    return names


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("pairs", type=Path)
    parser.add_argument("master", type=int)
    parser.add_argument("groups")
    parser.add_argument("--takes", choices=("free", "true"), default="free")
    parser.add_argument("--form", choices=("column", "split", "six"), default="column")
    parser.add_argument("--pixels", choices=("all", "unclipped"), default="all")
    parser.add_argument("--core", choices=("package", "faint"), default="package")
    parser.add_argument("--high", type=float, default=1.0)
    parser.add_argument("--meter", choices=("mean", "luma"), default="mean")
    parser.add_argument("--zones", action="store_true")
    args = parser.parse_args()
    ((*_, camera),) = list(case_draws(args.case, [args.master]))
    true = np.reshape(camera.ccm, (3, 3))
    pairs = load_pairs(args.pairs, max_side=256)
    problem = lb.BlindingFrames(pairs, 0)
    laser = problem.laser_channel
    names = take_names(args.form, laser)
    true_takes = {}
    for (i, j), name in names.items():
        true_takes.setdefault(name, []).append(-true[i, j])
    true_takes = {k: float(np.mean(v)) for k, v in true_takes.items()}
    print(f"camera: tone {camera.tone}, true matrix {np.round(true, 3).tolist()}; laser channel {laser}")
    print(f"true takes in this form: { {k: round(v, 3) for k, v in true_takes.items()} }")

    package_specs = lb.BlindingFrames.param_specs

    def specs(self, effects):
        out = []
        for p in package_specs(self, effects):
            if not p.name.startswith("ccm_"):
                out.append(p)
                continue
            for name in dict.fromkeys(n for (_, j), n in names.items() if lb.CHANNELS[j] == p.name[4:]):
                if args.takes == "true":
                    v = true_takes[name]
                    out.append(
                        dataclasses.replace(p, name=name, init=v, low=max(v - 1e-3, 0.0), high=v + 1e-3)
                    )
                else:
                    out.append(dataclasses.replace(p, name=name, high=args.high))
        return out

    def matrix(params):
        take = torch.zeros(3, 3, dtype=torch.float64)
        for (i, j), name in names.items():
            take[i, j] = torch.as_tensor(params[name], dtype=torch.float64)
        return torch.eye(3, dtype=torch.float64) + torch.diag(take.sum(1)) - take

    def compose_raw_faint(self, effects, params, f, decode):
        colour, m = self.raw_laser_colour(params), lb.correction_matrix(params)
        share = (m @ colour)[laser].clamp(min=1e-6)
        ch = slice(laser, laser + 1)
        stored = lb.laser_irradiance(
            decode(f["beam"])[:, ch],
            decode(f["dark"])[:, ch],
            f["core_depth"][:, ch],
            f["core_radius"][:, ch],
            params,
        )
        raw = stored[:, 0] / share
        light = (decode(f["beam"]) - decode(f["dark"])).clamp(min=0.0)
        in_core, level = f["core_depth"][:, laser] > 0, torch.zeros_like(raw)
        for c in range(3):
            if c == laser:
                continue
            k = 3 - laser - c
            denominator = m[c, c] * colour[c] + m[c, k] * colour[k]
            usable = in_core & (f["core_depth"][:, c] == 0) & (light[:, c] > 4 / 255) & (denominator > 1e-3)
            take = usable & (light[:, c] > level)
            raw = torch.where(
                take, ((light[:, c] - m[c, laser]) / denominator.clamp(min=1e-3)).clamp(min=1.0), raw
            )
            level = torch.where(take, light[:, c], level)
        beam = f["strength"] * f["exposure"] * lb.laser_gain(params) * raw.unsqueeze(1) * colour
        return self.scene_light(effects, params, f, decode) + beam

    package_exposure_factor = lb.BlindingFrames.exposure_factor

    class LuminanceMeter:
        """What the package's meter reads of ``problem``, each pixel's light replaced by its luminance in all three
        channels, so that the meter's channel mean is the luminance."""

        def __init__(self, problem) -> None:
            self.problem, self.probe_features = problem, problem.probe_features

        @staticmethod
        def luminance(light: torch.Tensor) -> torch.Tensor:
            return (light @ torch.tensor(LUMA, dtype=torch.float64)).unsqueeze(1).expand(-1, 3)

        def compose(self, *args):
            return self.luminance(self.problem.compose(*args))

        def scene_light(self, *args):
            return self.luminance(self.problem.scene_light(*args))

    def exposure_factor_luminance(self, effects, params, decode, probes=None):
        return package_exposure_factor(LuminanceMeter(self), effects, params, decode, probes)

    lb.BlindingFrames.param_specs = specs
    lb.correction_matrix = matrix
    if args.meter == "luma":
        lb.BlindingFrames.exposure_factor = exposure_factor_luminance
    if args.core == "faint":
        lb.BlindingFrames.compose_raw = compose_raw_faint
    known = [p.clean.reshape(3, -1).amin(0) > 2.5 / 255 for p in pairs]
    if args.pixels == "unclipped":
        problem.samples = [s[known[i][s]] for i, s in enumerate(problem.samples)]
    items = np.arange(problem.n_items)
    for group in args.groups.split(","):
        fit = problem.fit(frozenset(group.split("+")), items)
        squared, count, zones = 0.0, 0, {}
        for i in items:
            pair = pairs[int(i)]
            with torch.no_grad():
                residual = (255.0 * (problem.predict_pair(fit, int(i)) - pair.attacked)).numpy()
            scored = residual.reshape(3, -1)[:, known[int(i)]] if args.pixels == "unclipped" else residual
            squared, count = squared + float((scored**2).sum()), count + scored.size
            beam = pair.pattern.numpy()[laser]
            y0, x0 = np.unravel_index(np.argmax(beam), beam.shape)
            yy, xx = np.mgrid[0 : beam.shape[0], 0 : beam.shape[1]]
            r = np.hypot(yy - y0, xx - x0)
            for zone, inside in {
                "r<5": r < 5,
                "5-10": (r >= 5) & (r < 10),
                "10-20": (r >= 10) & (r < 20),
                "20+": r >= 20,
            }.items():
                z = zones.setdefault(zone, np.zeros(4))
                z[:3] += [(residual[c][inside] ** 2).sum() for c in range(3)]
                z[3] += inside.sum()
        shown = {k: round(float(v), 3) for k, v in fit.params.items()}
        print(
            f"{group} ({args.takes} takes, {args.form}, {args.pixels} pixels, {args.core} core, high {args.high:g}): "
            f"{args.meter} meter: RMSE {np.sqrt(squared / count):.2f}; {shown}",
            flush=True,
        )
        if args.zones:
            for zone, z in zones.items():
                print(
                    f"    {zone} px: mean squared error R G B {np.round(z[:3] / max(z[3], 1), 1).tolist()} ({int(z[3])} px)"
                )


if __name__ == "__main__":
    main()
