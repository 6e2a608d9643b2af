"""The two tests of 5d340f2 (``tests/calibration/test_noise.py``) read both ways: with the EM colour strip's noise
sources (the package) and with every value read at its own signal (``FrameProblem``'s default, the package before).
Prints the figures the tests assert on: measured over modelled variance on decoded rows and the rest, and the
variance-by-row test's eta2 interval, on the tests' seeds and three more.
Usage: ``PYTHONPATH=.:tests/calibration:tests python docs/bench/session74/without_sources_check.py``."""

import test_noise

from lerobot_phantom.calibration.frame_models.common import FrameProblem
from lerobot_phantom.calibration.frame_models.em_color_strip import EMStripFrames


def figures(seed: int) -> str:
    ratios = test_noise.variance_ratios_on_decoded_rows(seed)
    by_row = test_noise.variance_by_row_test(seed)
    interval = by_row["interval"]
    return (
        f"measured/modelled decoded {ratios[0]:.2f}, rest {ratios[1]:.2f}; variance by row eta2 "
        f"{interval['estimate']:.4f} ({interval['low']:.4f}-{interval['high']:.4f}), significant {by_row['significant']}"
    )


def main() -> None:
    with_sources = EMStripFrames.noise_sources
    for label, sources in (("with noise sources", with_sources), ("without (each value its own)", None)):
        EMStripFrames.noise_sources = with_sources if sources else FrameProblem.noise_sources
        print(label)
        for seed in (3, 4, 5, 6, 7):
            print(f"  seed {seed}: {figures(seed)}")


if __name__ == "__main__":
    main()
