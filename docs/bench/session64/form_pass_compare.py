"""One camsim case on the same master seeds, two packages: what each names, whether every planted effect is named,
the written model's held-out RMSE, and the repeated selection passes of the second (``selection.form_passes``).

Usage: ``PYTHONPATH=. python docs/bench/session64/form_pass_compare.py CASE BEFORE_DIR AFTER_DIR`` (each DIR an
OUTDIR of ``docs/bench/camsim_core_batch.sh``: ``bt_SEED/camsim0/CASE/out/report.json``).
"""

from __future__ import annotations

import json
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from camsim_case_cameras import case_draws


def reports(folder: Path, case: str) -> dict[int, dict]:
    return {
        int(path.parts[-5].removeprefix("bt_")): json.loads(path.read_text())
        for path in folder.glob(f"bt_*/camsim0/{case}/out/report.json")
    }


def main() -> None:
    case_name, before_dir, after_dir = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    before, after = reports(before_dir, case_name), reports(after_dir, case_name)
    seeds = sorted(set(before) & set(after))
    named_count = {"before": 0, "after": 0}
    changed = []
    for master, sim, case, seed, _rng, camera in case_draws(case_name, seeds):
        line = [f"master {master} (case seed {seed}, {camera.tone})"]
        for side, report in (("before", before[master]), ("after", after[master])):
            named = sim.named_causes(report)
            ok = case.planted <= named
            named_count[side] += ok
            line.append(
                f"  {side}: named {sorted(named)}; planted all named: {ok}; held-out "
                f"{report['extended']['heldout_rmse']:.3f} (base {report['base']['heldout_rmse']:.3f})"
            )
        for repeat in after[master]["selection"].get("form_passes", []):
            line.append(
                f"  repeat without {repeat['without']}: {repeat['selected']} at {repeat['validation_error']:.3f} "
                f"against {repeat['first_selected']} at {repeat['first_validation_error']:.3f}; taken: "
                f"{repeat['taken']}"
            )
        written = before[master]["extended"]["heldout_rmse"], after[master]["extended"]["heldout_rmse"]
        if written[0] != written[1]:
            changed.append(written)
        print("\n".join(line))
    print(
        f"{len(seeds)} seeds; every planted effect named: {named_count['before']} before, {named_count['after']} "
        f"after; the written model changed on {len(changed)}"
        + (
            f", held-out lower on {sum(b > a for b, a in changed)}, median ratio before/after "
            f"{statistics.median(b / a for b, a in changed):.3f}"
            if changed
            else ""
        )
    )


if __name__ == "__main__":
    main()
