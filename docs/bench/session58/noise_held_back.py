"""Photon noise and the fit pairs' structure, per camsim case: ``python noise_held_back.py ROOT...``.

Each ROOT is a pytest basetemp of ``test_independent_sim.py`` (``CAMSIM_SEED=<seed> CAMSIM_CASES=<cases>``); every
``report.json`` under it gives one line: case, shot_noise named, what conditions 1-4 of noise.py said, the fit
pairs' structure (condition 5), the held-out structure of the report, and the photon share.
"""

import json
import sys
from pathlib import Path


def main() -> None:
    print("seed | case | named | reasons 1-4 | fit-pair structure | held-out structure | photon share")
    for root in sys.argv[1:]:
        seed = Path(root).name.removeprefix("b_")
        for path in sorted(Path(root).glob("**/out/report.json")):
            report = json.loads(path.read_text())
            noise = report["noise"]
            line = f"{seed} | {path.parent.parent.name} | {noise['kept']}"
            if "shot_share" not in noise:  # no unclipped pixel to judge the noise by
                print(f"{line} | {noise['reasons']}")
                continue
            structure = noise.get("fit_items_structure")  # read only where conditions 1-4 named it
            held_back = sum("leaves structure in the fit pairs" in r for r in noise["reasons"])
            fit_pairs = "not read (1-4 failed)" if structure is None else structure["structure_remains"]
            print(
                f"{line} | {len(noise['reasons']) - held_back} | {fit_pairs} | "
                f"{report['unexplained_structure']['structure_remains']} | {noise['shot_share']['estimate']:.2f}"
            )


if __name__ == "__main__":
    main()
