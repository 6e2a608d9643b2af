"""camsim's ``projection_clipping`` case per master seed: the camera's full-well share of the ADC (the planted white
level, in linear light), the white level the written model fitted, and the last two selection steps with what the
clip scored on top of the last one when it was not taken.

Usage: ``CAMSIM_CASES=projection_clipping python docs/bench/camsim_clipping_white.py OUTDIR`` from the repository
root, on the output of ``CAMSIM_CASES=projection_clipping docs/bench/camsim_core_batch.sh TREE OUTDIR SEED...``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from camsim_named_causes import case_results


def main(out: Path) -> None:
    for seed, _sim, _case, report, judged in case_results(out):
        camera = judged["camera"]
        steps = report["selection"]["steps"]
        white = report["extended"]["params"].get("white")
        last = steps[-1]
        clip_next = {k: round(v, 3) for k, v in last["tried"].items() if "clipping" in k}
        print(
            f"{seed:>11} {camera.tone:6s} full-well share {camera.well_share_of_adc:.3f} "
            f"fitted white {'-' if white is None else f'{white:.3f}'} "
            f"{'named' if judged['passed'] else 'MISS '} "
            + " -> ".join(
                f"{'+'.join(s['effects']) or 'base'} {s['validation_error']:.3f}" for s in steps[-2:]
            )
            + (f"; clip tried next: {clip_next}" if clip_next else "")
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]))
