"""ISP forms a camera could add to light projection, fitted to a SLAP colour-triple table and not kept.

Fits on the calibration's fit rows (seed 0, 20% held out: ``core.seeded_split``), scores on its held-out rows and by
4-fold cross-validation on the fit rows (``core.selection_folds``), beside the written model (additive light with
cross-talk, and on the stop sign the reflectance term):

0. where the written model's squared error sits: rows whose capture has a channel at 250 or more, and the mean
   residual of a channel that is not saturated where another is;
1. ``spill``: light a channel clips is spilled, a fitted share of what exceeds white, into the pixel's others;
2. ``toward_max``: a pixel past white is pulled towards its brightest channel by a fitted share of the excess;
3. ``ccm``: the camera's colour correction matrix ``M`` (rows summing to 1): the reflectance modulates the projected
   light in the raw channels, ``M^-1`` of the stored surface colour, and ``M`` mixes the sum; with off-diagonals in
   [-1, 0.5] and, physical for a matrix that takes colour filters' overlap back out, in [-1, 0].

usage: PYTHONPATH=. python docs/bench/session66/slap_isp_probe.py TABLE.csv > out.txt
"""

import sys
from pathlib import Path

import numpy as np
import torch

from lerobot_phantom.calibration import projection as pj
from lerobot_phantom.calibration.core import Param, fit_least_squares, seeded_split, selection_folds

OFF = [f"ccm_{i}{j}" for i in range(3) for j in range(3) if i != j]


def ccm_matrix(params) -> torch.Tensor:
    rows = []
    for i in range(3):
        off = {j: torch.as_tensor(params[f"ccm_{i}{j}"], dtype=torch.float64) for j in range(3) if j != i}
        rows.append(torch.stack([1.0 - sum(off.values()) if j == i else off[j] for j in range(3)]))
    return torch.stack(rows)


class Probe:
    def __init__(self, path: Path) -> None:
        self.table = pj.TripleProblem(path)
        self.albedo = "stop_sign" in path.name  # the written models of both tables (README)
        self.fit_items, self.heldout = seeded_split(self.table.n_items, 0.2, 0)

    def predict(self, form: str, params, idx) -> torch.Tensor:
        idx = torch.as_tensor(idx)
        surface, projected = self.table.surface[idx], self.table.projected[idx]
        crosstalk = torch.stack([torch.as_tensor(params[n], dtype=torch.float64) for n in pj.CROSSTALK_NAMES])
        light = projected @ crosstalk.reshape(3, 3).T
        if form.startswith("ccm"):
            matrix = ccm_matrix(params)
            raw = surface @ torch.linalg.inv(matrix).T
            added = (light * (raw + params["reflectance_floor"]).clamp(min=0)) @ matrix.T
        elif self.albedo:
            added = light * (surface + params["reflectance_floor"]).clamp(min=0)
        else:
            added = light
        total = surface + added
        top = total.max(1, keepdim=True).values
        excess = (top - 1.0).clamp(min=0)
        if form == "spill":
            total = total + params["share"] * excess
        elif form == "toward_max":
            total = total + (params["share"] * excess / top.clamp(min=1e-9)).clamp(max=1) * (top - total)
        return total.clamp(0, 1)

    def specs(self, form: str) -> list[Param]:
        specs = [Param(n, 0.3 if n[-1] == n[-2] else 0.0, -5, 5, scale=0.3) for n in pj.CROSSTALK_NAMES]
        if self.albedo or form.startswith("ccm"):
            specs.append(Param("reflectance_floor", 0.1, -0.5, 2.0, scale=0.1))
        if form in ("spill", "toward_max"):
            specs.append(Param("share", 0.1, 0.0, 5.0, scale=0.1))
        if form.startswith("ccm"):
            high = 0.0 if form == "ccm_physical" else 0.5
            specs += [Param(n, -0.1, -1.0, high, scale=0.1) for n in OFF]
        return specs

    def fit(self, form: str, items) -> dict:
        target = self.table.captured[torch.as_tensor(items)]
        return fit_least_squares(
            self.specs(form),
            lambda p: (self.predict(form, p, items) - target).ravel(),
            tr_solver="exact",
            max_nfev=400,
        )

    def rmse(self, form: str, params, items) -> float:
        with torch.no_grad():
            t = {k: torch.tensor(v) for k, v in params.items()}
            error = 255 * (self.predict(form, t, items) - self.table.captured[torch.as_tensor(items)])
            return float(error.pow(2).mean().sqrt())

    def where(self) -> None:
        params = self.fit("written", self.fit_items)
        every = np.arange(self.table.n_items)
        with torch.no_grad():
            t = {k: torch.tensor(v) for k, v in params.items()}
            predicted = self.predict("written", t, every).numpy() * 255
        captured = self.table.captured.numpy() * 255
        residual = predicted - captured
        squared = (residual**2).sum(1)
        bright = captured.max(1) >= 250
        print(
            f"  rows with a captured channel >= 250: {bright.mean():.3f} of rows, {squared[bright].sum() / squared.sum():.3f}"
            " of the squared error"
        )
        for c in range(3):
            other = bright & (captured[:, c] < 250)
            print(
                f"  channel {'rgb'[c]}: mean residual (predicted - captured) {residual[other, c].mean():+.2f} where "
                f"another channel is saturated ({other.sum()} rows), {residual[~bright, c].mean():+.2f} where none is"
            )


def main() -> None:
    path = Path(sys.argv[1])
    probe = Probe(path)
    print(f"{path.name} ({probe.table.n_items} rows, {len(probe.heldout)} held out)")
    probe.where()
    for form in ("written", "spill", "toward_max", "ccm", "ccm_physical"):
        params = probe.fit(form, probe.fit_items)
        folds = [
            probe.rmse(form, probe.fit(form, train), left_out)
            for train, left_out in selection_folds(probe.fit_items, 4, 0)
        ]
        line = (
            f"  {form}: fit {probe.rmse(form, params, probe.fit_items):.2f}, held-out "
            f"{probe.rmse(form, params, probe.heldout):.2f}, 4-fold CV {np.sqrt(np.mean(np.square(folds))):.2f}"
        )
        if "share" in params:
            line += f", share {params['share']:.3f}"
        if form.startswith("ccm"):
            line += f", M {np.round(ccm_matrix({k: torch.tensor(v) for k, v in params.items()}).numpy(), 2).tolist()}"
        print(line, flush=True)


if __name__ == "__main__":
    main()
