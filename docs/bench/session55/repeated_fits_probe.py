"""How many of one calibration's fits repeat an earlier fit of the same model, items and start, and what they cost.

    python repeated_fits_probe.py ATTACK PLANTED SEED      (PLANTED: effects joined by "+", as the kit's cases)

Runs the calibration kit's case (tests/calibration/calibration_testkit.py) at the package code on PYTHONPATH with
every frame problem's ``fit`` counted. A repeat is recomputed, timed and compared with the first result ("unequal":
repeats whose parameters differ, a fit that is not a function of its effects, items and start); then the first result
is returned, as ``Problem.fits_kept`` does, so that fits started from it repeat too.
Run it on code before ``Problem.fits_kept`` (e604642): with the kept fits there are no repeats left to count.
"""

import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "calibration"))
import calibration_testkit as kit

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.frame_models import FRAME_PROBLEMS


def counted(problem_class, stats: dict, first: dict) -> None:
    fit = problem_class.fit

    def fit_and_count(self, effects, items, start=None):
        key = (id(self), frozenset(effects), items.tobytes(), None if start is None else id(start))
        began = time.perf_counter()
        result = fit(self, effects, items, start)
        seconds = time.perf_counter() - began
        stats["calls"] += 1
        stats["fit_s"] += seconds
        if key in first:
            stats["repeats"] += 1
            stats["repeat_s"] += seconds
            stats["unequal"] += first[key][1].params != result.params
            # the kept fit goes on, as with Problem.fits_kept, so later fits started from it are keyed alike
            return first[key][1]
        first[key] = (start, result)  # the start is kept, so its id is not reused
        return result

    problem_class.fit = fit_and_count


def main() -> None:
    attack, planted, seed = sys.argv[1], set(filter(None, sys.argv[2].split("+"))), int(sys.argv[3])
    stats = {"calls": 0, "repeats": 0, "unequal": 0, "fit_s": 0.0, "repeat_s": 0.0}
    first: dict = {}
    for problem_class in set(FRAME_PROBLEMS.values()):
        counted(problem_class, stats, first)
    with tempfile.TemporaryDirectory() as scratch:
        measured = Path(scratch) / "measured"
        measured.mkdir()
        kit.RENDERERS[attack](measured, planted, seed)
        began = time.perf_counter()
        report = calibrate(
            CalibrateConfig(attack=attack, measured=str(measured), out=f"{scratch}/out", seed=seed)
        )
        wall = time.perf_counter() - began
    withdrawn = [w["effect"] for w in report["selection"]["withdrawn"]]
    rounded = {k: round(v, 1) if isinstance(v, float) else v for k, v in stats.items()}
    print(
        f"{attack} {sorted(planted)} {seed} wall {wall:.1f} s {json.dumps(rounded)} "
        f"named {report['extended']['effects']} withdrawn {withdrawn}"
    )


if __name__ == "__main__":
    main()
