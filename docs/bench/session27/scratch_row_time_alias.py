import sys
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.core import Fit, fit_least_squares, seeded_split, single_threaded
from lerobot_phantom.calibration.stripes import StripeProblem

problem = StripeProblem(Path(sys.argv[1]), image_height=1080, exposure_unit_s=1e-6)
fit_items, held = seeded_split(problem.n_items, 0.2, int(sys.argv[2]))
eff = frozenset({"exposure_overlap", "integration_offset"})
rt, off = float(sys.argv[3]), float(sys.argv[4])
with single_threaded():
    full = problem.fit(eff, fit_items)
    t = torch.as_tensor(problem.rows[fit_items])
    for rule in ("all", "lit", "interior"):
        p = fit_least_squares(
            problem.param_specs(eff),
            lambda p, rule=rule: problem.predict(eff, p, fit_items, rule) - t,
            warm={"row_time_s": rt, "integration_offset_s": off},
        )
        f = Fit(eff, p, {"frames": rule})
        print(
            rule,
            {k: round(v * 1e6, 2) for k, v in p.items()},
            "fit rmse",
            np.sqrt(np.mean(problem.residual(f, fit_items) ** 2)).round(2),
            "held",
            np.sqrt(np.mean(problem.residual(f, held) ** 2)).round(2),
        )
    print(
        "chosen",
        {k: round(v * 1e6, 2) for k, v in full.params.items()},
        full.extra,
        np.sqrt(np.mean(problem.residual(full, fit_items) ** 2)).round(2),
    )
