"""The rolling-shutter kernel against the independent simulator of ``tests/calibration/test_stripes.py``.

For each seed and frame rule, the draw of ``test_phase_averaged_rows_match_the_simulator`` is repeated and the
condition with the largest miss (distance from the kernel's band over the test's tolerance; above 1 fails the test)
is printed with its regime: the pulse on-time and the exposure window against the row time, and how many of the 12
conditions kept a frame (the test asks for 6). Run from the repository
root:

    OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 python docs/bench/stripe_kernel_vs_simulator.py 2577942692 2677795359 1 2 3

(with ``PYTHONPATH`` pointing at the checkout whose package is measured; ``--frames N`` simulates N frames per
condition instead of the test's 300).
"""

import argparse
import importlib
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path("tests/calibration").resolve()))


def main(seeds: list[int], n_frames: int) -> None:
    failures, too_few_kept, cases = 0, 0, 0
    for seed in seeds:
        os.environ["STRIPES_SEED"] = str(seed)
        import test_stripes

        sim = importlib.reload(test_stripes)
        for frames in sim.physics.STRIPE_FRAME_RULES:
            check = sim.kernel_against_simulator(seed, frames, n_frames)
            miss = np.nan_to_num(sim.kernel_miss(check), nan=-np.inf)
            worst = int(np.argmax(miss))
            camera = check["camera"]
            frequency, duty, exposure = check["conditions"][worst]
            on, window = duty / frequency, exposure + camera["offset"]
            failed = bool(miss[worst] > 1.0)
            kept = int(np.isfinite(sim.kernel_miss(check)).sum())
            failures, too_few_kept, cases = failures + failed, too_few_kept + (kept < 6), cases + 1
            print(
                f"{seed:>10} {frames:8s} worst miss {miss[worst]:5.2f}: kernel {check['kernel'][worst]:7.1f} "
                f"(band {check['kernel_low'][worst]:.1f}-{check['kernel_high'][worst]:.1f}) simulator "
                f"{check['simulated'][worst]:7.1f} (standard error {check['standard_error'][worst]:4.1f}) rows at "
                f"{frequency:g} Hz, {duty:.0%} duty, on {on / camera['row_time']:.2f} and window "
                f"{window / camera['row_time']:.2f} row times, {kept} of 12 kept{'  FAIL' if failed else ''}{'  TOO FEW KEPT' if kept < 6 else ''}",
                flush=True,
            )
    print(
        f"kernel outside the tolerance: {failures} of {cases}; fewer than 6 conditions kept: {too_few_kept} of {cases}"
    )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("seeds", type=int, nargs="+")
    parser.add_argument("--frames", type=int, default=300)
    args = parser.parse_args()
    main(args.seeds, args.frames)
