"""The grey level at which a written light projection model's clip cuts: its linear-light white encoded through the
written tone curve (the shoulder, under the fitted display gamma where there is one). Usage: ``PYTHONPATH=. python
docs/bench/session77/clip_white_levels.py REPORT_JSON...``."""

import json
import sys
from pathlib import Path

import torch

from lerobot_phantom.calibration.projection import tone_curve


def main() -> None:
    for path in sys.argv[1:]:
        extended = json.loads(Path(path).read_text())["extended"]
        params, effects = extended["params"], frozenset(extended["effects"])
        if "clipping" not in effects:
            continue
        _decode, encode = tone_curve(effects, params)
        level = 255 * float(encode(torch.tensor([params["white"]], dtype=torch.float64))[0])
        shown = ", ".join(
            f"{k} {params[k]:.3g}" for k in ("white", "shoulder", "shoulder_exponent", "gamma") if k in params
        )
        print(f"{path}: {shown}; the clip at {level:.1f} of 255")


if __name__ == "__main__":
    main()
