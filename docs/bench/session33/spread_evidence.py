"""Scratch check (session 33, not kept in the package): the table's frames' spread (``affected_rows_std``) as
evidence for a recording's drift. The ``phase_drift`` model (start at any whole placement) fitted on a split's fit
rows by the package, then refitted with each fit row's predicted frames' spread (the spread over the drift arc, with
the fit rows' median spread as a floor) stacked beside its mean. Prints held-out RMSE and fitted drifts only.

Usage: ``python docs/bench/session33/spread_evidence.py TABLE SEED`` (the Axis table, 720 rows, microseconds).
"""

import sys
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration.core import Fit, fit_least_squares, seeded_split
from lerobot_phantom.calibration.stripes import DRIFT_JACOBIAN, StripeProblem
from lerobot_phantom.transforms import physics as ph


# predicted frames' spread of a drifting recording: sqrt(var over the arc + floor^2), averaged over placements
def spread_pred(pr, params, items, floor):
    f = torch.as_tensor(pr.frequency_hz[items])
    period = 1 / f
    on = torch.as_tensor(pr.duty[items]) * period
    window = (torch.as_tensor(pr.exposure_s[items]) + params["integration_offset_s"]).clamp(min=0)
    rt = torch.as_tensor(params["row_time_s"], dtype=torch.float64)
    reached = ph.pulse_overlap_lit_time(period, on, window, 0.0, None)
    p, w = period / rt, reached / rt
    H = torch.tensor(720.0, dtype=torch.float64)
    edge = H - 1
    drift = torch.stack([torch.as_tensor(params[n], dtype=torch.float64) for n in pr.drift_names], -1)[
        torch.as_tensor(pr.recording[items])
    ]
    pl = ph._interior_placements(p, w, edge)
    grid = (torch.arange(16, dtype=torch.float64) + 0.5) / 16
    st = []
    wt = []
    for lo, _, ln in pl:
        c = lo.unsqueeze(-1) + ln.unsqueeze(-1) * grid
        st.append(edge - c)
        wt.append((ln / 16).unsqueeze(-1).expand_as(c))
    s0 = torch.cat(st, -1)
    W = torch.cat(wt, -1)
    arc = (torch.arange(64, dtype=torch.float64) + 0.5) / 64
    s = s0.unsqueeze(-1) + (drift * p).unsqueeze(-1).unsqueeze(-1) * arc
    p3, w3 = p[:, None, None], w[:, None, None]
    rows = ph.cumulative_on_time(H - s, p3, w3) - ph.cumulative_on_time(-s, p3, w3)
    lit = (rows > 1e-9).double()
    n = lit.sum(-1).clamp(min=1)
    m = (rows * lit).sum(-1) / n
    v = ((rows**2) * lit).sum(-1) / n - m**2
    sd = torch.sqrt(v.clamp(min=0) + floor**2)
    return (sd * W).sum(-1) / W.sum(-1).clamp(min=1e-300)


seed = int(sys.argv[2]) if len(sys.argv) > 2 else 0
pr = StripeProblem(Path(sys.argv[1]), image_height=720, exposure_unit_s=1e-6)
fit, held = seeded_split(pr.n_items, 0.2, seed)
E = frozenset({"exposure_overlap", "integration_offset", "phase_drift"})
f = pr.fit(E, fit)
floor = float(np.median(pr.spread[fit]))
target = torch.as_tensor(pr.rows[fit])
starget = torch.as_tensor(pr.spread[fit])


def res(p):
    return torch.cat([pr.predict(E, p, fit, "interior") - target, spread_pred(pr, p, fit, floor) - starget])


p2 = fit_least_squares(pr.param_specs(E), res, warm=f.params, jacobian=DRIFT_JACOBIAN)
f2 = Fit(E, p2, {"frames": "interior"})
print(
    seed,
    "means only: held",
    round(pr.rmse(f, held), 2),
    "drift50",
    round(f.params["drift_25Hz_exposure50"], 3),
    "| with spread: held",
    round(pr.rmse(f2, held), 2),
    {k: round(v, 3) for k, v in p2.items() if "drift" in k},
)
