"""``StripFrames.predict_stripes`` against ``predict_stripe`` pair by pair, to the bit, on the calibration kit's frames.

    python stripe_rows_together.py      (the package on PYTHONPATH must have predict_stripes: 5ffb16a or later)

Kit cases 62, 63 and 64 (frames of distinct heights), 20 random stripe parameter sets each (every other one with a
pulse period, every third with a power-law gamma) and a random pulse phase per pair.
"""

import sys
import tempfile
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
import calibration_testkit as kit

from lerobot_phantom.calibration.frame_models import FRAME_PROBLEMS, load_pairs


def main() -> None:
    differ = total = 0
    for planted, seed in [
        ({"exposure_overlap"}, 62),
        ({"exposure_overlap", "stripe_period"}, 63),
        ({"exposure_overlap", "sensor_gamma"}, 64),
    ]:
        with tempfile.TemporaryDirectory() as scratch:
            kit.RENDERERS["laser_color_strip"](Path(scratch), planted, seed)
            problem = FRAME_PROBLEMS["laser_color_strip"](load_pairs(Path(scratch), max_side=256), seed)
        items = np.arange(len(problem.pairs))
        print(f"case {seed}: frame heights {sorted({p.height for p in problem.pairs})}")
        rng = np.random.default_rng(seed)
        for trial in range(20):
            params = {f"peak_{c}": rng.uniform(0, 2) for c in "rgb"}
            params.update(on_share=rng.uniform(0.01, 0.5), exposure_share=rng.uniform(0, 0.5))
            if trial % 2:
                params["period_share"] = rng.uniform(0.05, 2.0)
            if trial % 3 == 0:
                params["gamma"] = rng.uniform(0.5, 3)
            params = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
            phases = {int(i): float(rng.uniform(-30, 60)) for i in items}
            with torch.no_grad():
                together = problem.predict_stripes(params, items, phases)
                for predicted, i in zip(together, items, strict=True):
                    total += 1
                    differ += not torch.equal(
                        predicted, problem.predict_stripe(params, int(i), phases[int(i)])
                    )
    print(f"frames differing in any bit: {differ} of {total}")


if __name__ == "__main__":
    main()
