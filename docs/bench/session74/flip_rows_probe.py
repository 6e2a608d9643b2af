"""What the Bayer-flip model leaves on the rows it decodes (camsim's em_strip_bayer_flip): RMSE (grey levels) on
those rows of the written colour map applied to the clean frame's same row, to the next row (the lost line
shifts the raw rows by one), to their mean, and each of those mapped in linear light (sRGB decoded, map with gain 1
and offset 0, encoded); beside it the RMSE on the rows left as they are (clean against attacked).
Usage: ``PYTHONPATH=. python docs/bench/session74/flip_rows_probe.py CASE_DIR...`` (each holds ``pairs/`` and
``out/report.json``, as ``session73/variance_probe.py`` leaves them; frames read at 128 px, the runs' size)."""

import json
import sys
from pathlib import Path

import torch

from lerobot_phantom.calibration.core import Fit
from lerobot_phantom.calibration.frame_models.common import load_pairs
from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames
from lerobot_phantom.transforms import physics


def rmse_by_source(case: Path) -> dict[str, float]:
    report = json.loads((case / "out/report.json").read_text())
    pairs = load_pairs(case / "pairs", max_side=128)
    problem = EMStripFrames(pairs, seed=0)
    fit = Fit(frozenset(report["extended"]["effects"]), dict(report["extended"]["params"]))
    squared: dict[str, float] = {}
    decoded_count, plain_count = 0, 0
    for index, pair in enumerate(pairs):
        placement = problem.placements(fit.effects, fit.params, [index])[index]
        rows = problem.mask(fit.effects, fit.params, index, placement)[0, :, 0].numpy() > 0
        rows[-1] = False  # the last row has no next row
        clean = pair.clean
        below = torch.cat([clean[:, 1:], clean[:, -1:]], 1)
        for name, source in (
            ("same row", clean),
            ("next row", below),
            ("mean of the two", 0.5 * (clean + below)),
        ):
            mapped = physics.em_color_map(source.unsqueeze(0), fit.params["gain"], fit.params["offset"])[0]
            linear = physics.encode(
                physics.em_color_map(physics.decode(source.unsqueeze(0), None), 1.0, 0.0), None
            )[0]
            for label, image in ((name, mapped), (f"{name}, linear", linear)):
                squared[label] = squared.get(label, 0.0) + float(
                    ((255 * (image - pair.attacked))[:, rows] ** 2).sum()
                )
        squared["rows left as they are"] = squared.get("rows left as they are", 0.0) + float(
            ((255 * (clean - pair.attacked))[:, ~rows] ** 2).sum()
        )
        decoded_count += 3 * int(rows.sum()) * pair.width
        plain_count += 3 * int((~rows).sum()) * pair.width
    return {
        k: (v / (plain_count if k == "rows left as they are" else decoded_count)) ** 0.5
        for k, v in squared.items()
    }


def main() -> None:
    for case in map(Path, sys.argv[1:]):
        figures = rmse_by_source(case)
        print(f"{case.parents[1].name} {case.name}: " + "; ".join(f"{k} {v:.2f}" for k, v in figures.items()))


if __name__ == "__main__":
    main()
