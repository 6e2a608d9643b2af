"""What a colour correction matrix leaves of light projection frames when the model knows the camera exactly.

Fits, on every pair of a camsim light projection draw (800 sampled pixels a pair, as the calibration's fits), the
library's projection models with camsim's own filmic tone curve in place of the fitted one and, for
``colour_correction``, the camera's true matrix held fixed; then splits the squared error of the last model by where
it falls. Needs the tree of ``projection_colour_correction_attempt.patch`` (the ``colour_correction`` term) and a
filmic camera.

Usage: ``[CAMSIM_CCM=1] PYTHONPATH=. python docs/bench/session67/projection_ccm_oracle.py CASE SEED PAIRS_DIR
EFFECTS[,EFFECT...]...``
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch
from scipy.ndimage import maximum_filter, minimum_filter

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws

import lerobot_phantom.calibration.frame_models.light_projection as frames
import lerobot_phantom.calibration.projection as projection
from lerobot_phantom.calibration.core import Param
from lerobot_phantom.calibration.frame_models.common import load_pairs


def srgb_decode(v: torch.Tensor) -> torch.Tensor:
    v = v.clamp(0, 1)
    return torch.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def aces(v):
    return v * (2.51 * v + 0.03) / (v * (2.43 * v + 0.59) + 0.14)


ACES_4 = float(aces(torch.tensor(4.0, dtype=torch.float64)))


def filmic_decode(v: torch.Tensor) -> torch.Tensor:
    """camsim's filmic curve (ACES on a 4x pre-gain, normalised, then sRGB) inverted: a quadratic in the pre-gain."""
    a = (srgb_decode(v) * ACES_4).clamp(max=ACES_4 * 0.9999)
    qa, qb, qc = 2.51 - 2.43 * a, 0.03 - 0.59 * a, -0.14 * a
    return ((-qb + torch.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)) / 4


def regions(pair) -> dict[str, np.ndarray]:
    pattern, clean = pair.pattern.numpy() * 255, pair.clean.numpy() * 255
    lit = pattern.max(0) > 20
    edge = (maximum_filter(pattern, size=(1, 5, 5)) - minimum_filter(pattern, size=(1, 5, 5))).max(0) > 20
    clean_zero = clean.min(0) <= 2
    pattern_zero = lit & (pattern.min(0) <= 2)
    pattern_white = pattern.max(0) >= 250
    return {
        "not lit by the pattern, away from its edges": ~lit & ~edge,
        "pattern edges (5x5 range > 20)": edge,
        "lit: clean has a channel at 0 (<= 2)": lit & ~edge & clean_zero,
        "lit: pattern has a channel at 0, clean none": lit & ~edge & pattern_zero & ~clean_zero,
        "lit: pattern at white (>= 250), no channel at 0": lit
        & ~edge
        & pattern_white
        & ~pattern_zero
        & ~clean_zero,
        "lit: none of these": lit & ~edge & ~clean_zero & ~pattern_zero & ~pattern_white,
    }


def main() -> None:
    case, seed, folder, models = sys.argv[1], int(sys.argv[2]), Path(sys.argv[3]), sys.argv[4:]
    (*_, camera), *_ = case_draws(case, [seed])
    if camera.tone != "filmic":
        raise SystemExit(
            f"{case} on {seed} draws a {camera.tone} camera; this oracle inverts camsim's filmic curve"
        )
    truth = None if camera.ccm is None else np.reshape(camera.ccm, (3, 3))
    print(
        f"{case} {seed}: camera tone {camera.tone}, colour correction {None if truth is None else truth.round(3).tolist()}"
    )
    import camsim

    def filmic_encode(x: torch.Tensor) -> torch.Tensor:
        return torch.from_numpy(camsim.tone_curve(x.numpy(), camera))

    exact = lambda effects, params: (filmic_decode, filmic_encode)  # noqa: E731
    projection.tone_curve = frames.tone_curve = exact
    specs = projection.projection_specs

    def true_matrix(effects):
        out = []
        for p in specs(effects):
            if p.name.startswith("ccm_") and truth is not None:
                v = float(truth[int(p.name[-2]), int(p.name[-1])])
                p = Param(p.name, v, v - 1e-4, v + 1e-4, scale=1e-4)
            out.append(p)
        return out

    projection.projection_specs = true_matrix
    pairs = load_pairs(folder, max_side=256)
    problem = frames.ProjectionFrames(pairs, 0)
    items = np.arange(len(pairs))
    for model in models:
        fit = problem.fit(frozenset(model.split(",")), items)
        sse, n = problem.squared_errors(fit, items)
        shown = {k: round(v, 3) for k, v in fit.params.items() if not k.startswith(("ccm_", "crosstalk_"))}
        print(f"  {model}: RMSE {np.sqrt(sse / n):.2f} grey levels, all pairs; {shown}")
    residual = np.stack(
        [problem.predict_pair(fit, int(i)).numpy() * 255 - pairs[i].attacked.numpy() * 255 for i in items]
    )
    masks = [regions(p) for p in pairs]
    total = float((residual**2).sum())
    print(
        f"  where the last model's squared error falls (per-channel RMSE {np.sqrt((residual**2).mean(axis=(0, 2, 3))).round(2).tolist()}):"
    )
    for name in masks[0]:
        m = np.stack([k[name] for k in masks])
        values = residual.transpose(1, 0, 2, 3)[:, m]
        print(
            f"    {name}: {m.mean():.1%} of pixels, RMSE {np.sqrt((values**2).mean()):.2f}, "
            f"{(values**2).sum() / total:.1%} of the squared error"
        )


if __name__ == "__main__":
    main()
