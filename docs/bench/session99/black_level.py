"""One camsim case draw scored structure by structure (session 98's ``structures.py``) at several black levels of
``physics.captured_light_to_raw``: the stored level at or below which a captured pattern's channel reads as black
(``physics.PATTERN_BLACK_LEVEL``, in grey levels here; -1: no channel at black, the whole matrix's inverse, the
package before session 99). Usage: ``CAMSIM_CCM=1 CAMSIM_SEED=1 PYTHONPATH=.:tests/calibration:tests python
docs/bench/session99/black_level.py LEVELS CASE CASE_SEED SET...`` (LEVELS: grey levels joined by ``,``)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "session98"))
import structures

from lerobot_phantom.transforms import physics


def main() -> None:
    levels, rest = sys.argv[1].split(","), sys.argv[2:]
    for level in levels:
        physics.PATTERN_BLACK_LEVEL = float(level) / 255
        print(f"black level {level} grey levels", flush=True)
        sys.argv = [sys.argv[0], *rest]
        structures.main()


if __name__ == "__main__":
    main()
