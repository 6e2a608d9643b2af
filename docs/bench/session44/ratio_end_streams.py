"""How much of rule 2's decision is Monte Carlo noise: one drawn second camera of ``test_stripes`` calibrated as
``test_second_camera_heldout_rows_and_parameters`` does (``calibrate_drawn_camera``), recording the per-item errors
of every error ratio identification computes; then, for each distinct ratio, the 5% end of its interval over many
generator streams at 200 draws (the count before session 44) and at the package's ``RESUMMED_DRAWS``. Run from a
checkout, whose package is what is measured:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session44/ratio_end_streams.py SEED lit|interior \
        OUT_DIR
"""

import os
import sys
from pathlib import Path

import numpy as np

seed, frames, out = int(sys.argv[1]), sys.argv[2], Path(sys.argv[3])
os.environ["STRIPES_SEED"] = str(seed)  # the test module draws its seed at import
sys.path.insert(0, str(Path("tests/calibration").resolve()))
from lerobot_phantom.calibration import identify  # noqa: E402

recorded = []
package_error_ratio = identify.error_ratio


def recording_error_ratio(before, after, **kwargs):
    recorded.append((np.array(before), np.array(after), kwargs.get("score", "rmse")))
    return package_error_ratio(before, after, **kwargs)


identify.error_ratio = recording_error_ratio
import test_stripes  # noqa: E402

out.mkdir(parents=True, exist_ok=True)
# the exposure column of each frame rule as second_camera_sweep.py writes it
style = {"lit": "exposure_us", "interior": "exposure"}[frames]
camera, report = test_stripes.calibrate_drawn_camera(out, seed, frames, style, seed % 1000)
print(
    f"camera {seed} {frames}: written {sorted(report['extended']['effects'])}, held-out "
    f"{report['extended']['heldout_rmse']:.2f} rows"
)
for withdrawal in report["selection"]["withdrawn"]:
    print(
        f"withdrawn in pass {withdrawal['pass']}: {withdrawal['effect']}: {'; '.join(withdrawal['reasons'])}"
    )
for result in report["identification"]:
    ratio = result.get("validation_ratio")
    if ratio:
        print(
            f"{result['effect']}: the tool's ratio {ratio['estimate']:.4f}, {ratio['low']:.4f}-{ratio['high']:.4f}"
        )
seen = set()
for before, after, score in recorded:
    key = (before.tobytes(), after.tobytes(), score)
    if key in seen:
        continue
    seen.add(key)
    estimate = package_error_ratio(before, after, draws=1, rng=np.random.default_rng(0), score=score).estimate
    line = f"ratio {estimate:.4f} ({score}, {len(before)} items):"
    for draws, streams in ((200, 200), (identify.RESUMMED_DRAWS, 40)):
        lows = np.array(
            [
                package_error_ratio(
                    before, after, draws=draws, rng=np.random.default_rng([k, 44]), score=score
                ).low
                for k in range(streams)
            ]
        )
        line += (
            f" {draws} draws: 5% end {lows.mean():.4f} +- {lows.std():.4f} over {streams} streams,"
            f" {np.mean(lows <= 1.0):.0%} at or below 1;"
        )
    print(line)
