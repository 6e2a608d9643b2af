"""Where an EM colour strip case's residual holds more or less variance than the noise model places, read on every
unclipped value of every pair under the report's written model (with ``bayer_demosaic``, since session 75, its fitted
tile): measured over modelled variance on the rows the
model decodes and on the rest, per channel, per eighth of the frame's height and per pair. The noise model is the
package's (``FrameProblem.noise_terms``, ``noise.fit_variance``) at the checkout on PYTHONPATH.
Usage: ``PYTHONPATH=. python docs/bench/session74/decoded_rows_noise.py CASE_DIR [MAX_SIDE]`` (CASE_DIR holds
``pairs/`` and ``out/report.json``, as ``session73/variance_probe.py`` leaves them; MAX_SIDE: the run's
``--capture-max-side``, 128)."""

import json
import sys
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames
from lerobot_phantom.calibration.noise import NoiseSample, fit_variance, model_variance, unclipped


def main() -> None:
    case = Path(sys.argv[1])
    report = json.loads((case / "out/report.json").read_text())
    pairs = load_pairs(case / "pairs", max_side=int(sys.argv[2]) if len(sys.argv) > 2 else 128)
    problem = EMStripFrames(pairs, seed=0)
    tile = report["extended"]["derived"].get("colour_filter_tile")
    fit = Fit(
        frozenset(report["extended"]["effects"]),
        dict(report["extended"]["params"]),
        {} if tile is None else {"pattern": tile},
    )
    samples, decoded, channel, row, pair_index = [], [], [], [], []
    for index, pair in enumerate(pairs):
        predicted, measured = 255.0 * problem.predict_pair(fit, index).numpy(), 255.0 * pair.attacked.numpy()
        everywhere = np.unravel_index(np.arange(predicted.size), predicted.shape)
        sample, _ = problem.noise_terms(fit, index, predicted, measured, everywhere)
        # the values noise_terms keeps, in its order
        kept = np.flatnonzero(unclipped(predicted.ravel(), measured.ravel()))
        c, y, _ = np.unravel_index(kept, predicted.shape)
        placement = problem.placements(fit.effects, fit.params, [index], tile)[index]
        rows_decoded = problem.mask(fit.effects, fit.params, index, placement)[0, :, 0].numpy() > 0
        samples.append(sample)
        decoded.append(rows_decoded[y])
        row.append(y * 8 // pair.height)
        pair_index.append(np.full(len(y), index))
        channel.append(c)
    joined = NoiseSample.join(samples)
    variance = model_variance(joined, fit_variance(joined, True))

    def ratio(where: np.ndarray) -> str:
        if not where.any():
            return "no unclipped values"
        return f"{np.mean(joined.residual[where] ** 2) / np.mean(variance[where]):.2f} ({where.sum()} values)"

    decoded, row, pair_index, channel = map(np.concatenate, (decoded, row, pair_index, channel))
    print(f"{case}: written model {sorted(fit.effects) or 'base'} {fit.params}")
    print(f"measured over modelled variance: decoded rows {ratio(decoded)}, the rest {ratio(~decoded)}")
    for c, name in enumerate("RGB"):
        print(
            f"  {name}: decoded rows {ratio(decoded & (channel == c))}, the rest {ratio(~decoded & (channel == c))}"
        )
    for b in range(8):
        print(f"  eighth {b} of the height: decoded share {decoded[row == b].mean():.2f}, {ratio(row == b)}")
    print("  per pair: " + ", ".join(ratio(pair_index == i).split(" ")[0] for i in range(len(pairs))))
    # a demosaicing pattern the colour map does not form alternates from pixel to pixel: neighbours anti-correlate
    lag1 = {name: [] for name in "RGB"}
    for index, pair in enumerate(pairs):
        residual = 255.0 * (problem.predict_pair(fit, index) - pair.attacked).numpy()
        placement = problem.placements(fit.effects, fit.params, [index], tile)[index]
        rows_decoded = problem.mask(fit.effects, fit.params, index, placement)[0, :, 0].numpy() > 0
        for c, name in enumerate("RGB"):
            on_rows = residual[c][rows_decoded]
            if on_rows.size > 2:
                lag1[name].append((on_rows[:, :-1].ravel(), on_rows[:, 1:].ravel()))
    print(
        "  lag-1 correlation along rows of the residual on decoded rows: "
        + ", ".join(
            f"{name} {np.corrcoef(np.concatenate([a for a, _ in v]), np.concatenate([b for _, b in v]))[0, 1]:+.2f}"
            for name, v in lag1.items()
            if v
        )
    )


if __name__ == "__main__":
    main()
