"""What a demosaic of the raw lines moved up by one leaves on the rows the Bayer-flip model decodes (camsim's
em_strip_bayer_flip), against the written colour map: the decoded rows' RMSE (grey levels) under the map of the
report's fit, and under OpenCV's bilinear demosaic (an implementation outside the package and camsim) of the clean
frame mosaicked with each of the four colour-filter tiles, its raw lines moved up by one, with the map's gain (red,
blue) and offset (green) fitted on those rows ("g": the fitted gain); "lin": mosaicked in linear light (sRGB
decoded), encoded after. Usage: ``PYTHONPATH=. python docs/bench/session75/demosaic_rows_probe.py CASE_DIR...``
(each holds ``pairs/`` and ``out/report.json``, as ``session73/variance_probe.py`` leaves them; the flip rows are
those the report's fit registers)."""

import json
import sys
from pathlib import Path

import cv2
import numpy as np
import torch
from scipy.optimize import least_squares

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames
from lerobot_phantom.transforms import physics

# OpenCV names a Bayer pattern by the second row's two first sites
OPENCV_CODES = {
    "RGGB": cv2.COLOR_BayerBG2RGB,
    "GRBG": cv2.COLOR_BayerGB2RGB,
    "GBRG": cv2.COLOR_BayerGR2RGB,
    "BGGR": cv2.COLOR_BayerRG2RGB,
}


def opencv_demosaic_after_lost_line(frame: torch.Tensor, tile: str, linear: bool) -> torch.Tensor:
    x = physics.decode(frame.unsqueeze(0), None)[0] if linear else frame
    x = x.numpy()
    _, height, width = x.shape
    sites = np.array(physics.BAYER_PATTERNS[tile])[
        np.arange(height)[:, None] % 2, np.arange(width)[None, :] % 2
    ]
    raw = np.take_along_axis(x, sites[None], 0)[0]
    raw = raw[np.minimum(np.arange(height) + 1, height - 1)]
    rgb = cv2.cvtColor(np.round(raw * 65535).astype(np.uint16), OPENCV_CODES[tile]).astype(np.float64) / 65535
    return torch.from_numpy(rgb.transpose(2, 0, 1))


def decoded_rows_rmse(case: Path) -> dict[str, float]:
    report = json.loads((case / "out/report.json").read_text())
    pairs = load_pairs(case / "pairs", max_side=128)
    problem = EMStripFrames(pairs, seed=0)
    fit = Fit(frozenset(report["extended"]["effects"]), dict(report["extended"]["params"]))
    rows = []
    for index in range(len(pairs)):
        placement = problem.placements(fit.effects, fit.params, [index])[index]
        decoded = problem.mask(fit.effects, fit.params, index, placement)[0, :, 0].numpy() > 0
        decoded[-1] = False  # the last row has no row below it
        rows.append(decoded)

    def rmse(images) -> float:
        squared = sum(
            float(((255 * (image - pair.attacked))[:, r] ** 2).sum())
            for pair, r, image in zip(pairs, rows, images, strict=True)
        )
        return (
            squared / sum(3 * int(r.sum()) * pair.width for pair, r in zip(pairs, rows, strict=True))
        ) ** 0.5

    figures = {"map": rmse([problem.colour_mapped(fit.params, i) for i in range(len(pairs))])}
    for linear in (False, True):
        for tile in physics.BAYER_PATTERNS:
            demosaiced = [opencv_demosaic_after_lost_line(pair.clean, tile, linear) for pair in pairs]

            def predict(colour, demosaiced=demosaiced, linear=linear):
                gain, offset = colour
                out = [torch.stack([gain * d[0], d[1] - offset, gain * d[2]]).clamp(0, 1) for d in demosaiced]
                return [physics.encode(o.unsqueeze(0), None)[0] for o in out] if linear else out

            def residuals(colour, predict=predict):
                return np.concatenate(
                    [
                        (255 * (image - pair.attacked))[:, r].numpy().ravel()
                        for pair, r, image in zip(pairs, rows, predict(colour), strict=True)
                    ]
                )

            start = (1.0, 0.0) if linear else (fit.params["gain"], fit.params["offset"])
            colour = least_squares(residuals, start, bounds=([0, -1], [10, 1])).x
            label = f"{tile}{' lin' if linear else ''}"
            figures[label] = rmse(predict(colour))
            figures[f"{label} g"] = float(colour[0])
    return figures


def main() -> None:
    for case in map(Path, sys.argv[1:]):
        figures = decoded_rows_rmse(case)
        print(f"{case.parents[1].name}: " + " ".join(f"{k} {v:.2f}" for k, v in figures.items()))


if __name__ == "__main__":
    main()
