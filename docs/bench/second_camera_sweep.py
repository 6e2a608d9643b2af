"""Second-camera stripe tables over seeds, every case's figures (passing ones too): held-out RMSE of the written
model and of the base, the named effects, the fitted row time against the camera's, and the 30-row bar.

``test_second_camera_heldout_rows_and_parameters`` reports only failures; this runs its draw and calibration
(``calibrate_drawn_camera``, the same seeds and flags) and prints one line per seed x frame rule. Run from the
checkout to measure (session 29):

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/second_camera_sweep.py SEED [SEED ...]

``--frames lit`` or ``--frames interior`` (before the seeds) runs one frame rule's cases only. ``groups`` gives
the number of new effects each selection step took, in order (session 58: a 3 is a group of three, which only
stripe tables score since session 57).
"""

import importlib
import itertools
import os
import sys
from pathlib import Path
from tempfile import TemporaryDirectory

sys.path.insert(0, str(Path("tests/calibration").resolve()))

CASES = (("lit", "exposure_us"), ("interior", "exposure"))


def groups_taken(steps: list[dict]) -> list[int]:
    """New effects per selection step taken: between two steps that scored groups (``tried``), the model grew by
    the group the first took; the steps inside a group (its prefixes) scored none."""
    deciding = [k for k, step in enumerate(steps) if step["tried"]]
    if steps and not steps[-1]["tried"]:  # every candidate taken: the last model had none left to score
        deciding.append(len(steps) - 1)
    return [len(steps[j]["effects"]) - len(steps[i]["effects"]) for i, j in itertools.pairwise(deciding)]


def main(seeds: list[int], cases_run=CASES) -> None:
    above, cases = 0, 0
    for seed in seeds:
        # the test module draws its seed at import: reload it per seed
        os.environ["STRIPES_SEED"] = str(seed)
        import test_stripes

        sim = importlib.reload(test_stripes)
        for frames, style in cases_run:
            with TemporaryDirectory() as tmp:
                camera, report = sim.calibrate_drawn_camera(Path(tmp), seed, frames, style, seed % 1000)
            extended, base = report["extended"]["heldout_rmse"], report["base"]["heldout_rmse"]
            row_time = report["extended"]["params"].get("row_time_s", float("nan"))
            failed = extended > 30.0
            above, cases = above + failed, cases + 1
            print(
                f"{seed:>10} {frames:8s} held-out {extended:7.2f} rows (base {base:6.1f}) row time "
                f"{row_time * 1e6:6.1f} us (camera {camera['row_time'] * 1e6:5.1f}) named "
                f"{','.join(sorted(report['extended']['effects']))} groups "
                f"{','.join(map(str, groups_taken(report['selection']['steps']))) or '-'}"
                f"{'  ABOVE 30' if failed else ''}",
                flush=True,
            )
    print(f"held-out above 30 rows: {above} of {cases}")


if __name__ == "__main__":
    arguments = sys.argv[1:]
    chosen = CASES
    if arguments[:1] == ["--frames"]:
        rules = {frames: (frames, style) for frames, style in CASES}
        if len(arguments) < 2 or arguments[1] not in rules:
            raise SystemExit(f"--frames takes one of {', '.join(rules)}")
        chosen, arguments = (rules[arguments[1]],), arguments[2:]
    main([int(s) for s in arguments], chosen)
