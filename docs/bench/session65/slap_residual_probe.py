"""What the written model leaves in a SLAP colour-triple table's residual, and what would take it up.

Fits on the calibration's fit rows (seed 0, 20% held out: ``core.seeded_split``), scores on its held-out rows:

1. the written model (its effects refitted here) and, from the fit rows' residuals under it, three predictors of a
   held-out row's residual: the mean of the fit rows with the same surface colour; a strength of the added light
   per surface colour; the mean of the k fit rows nearest in surface colour under the same projected colour (k-NN,
   a function of the inputs with no physics: how far any model of these inputs could get);
2. a strength of the added light per row, fitted on the row itself (in sample: one number for three values), over
   the values that are not clipped;
3. other forms fitted and scored like the written model: the pattern's own transfer curve (a power law for the
   projector), reflectance weighting each projected primary instead of each camera channel, the light from each
   primary into each camera channel a linear function of the surface's three channels (36 numbers), and
   reflectance at each primary a linear function of the surface's channels (21 numbers; also with non-negative
   weights, as a reflectance must be).

0. the table itself (``table_facts``);

usage: PYTHONPATH=. python docs/bench/session65/slap_residual_probe.py TABLE.csv > out.txt
"""

import sys
from pathlib import Path

import numpy as np
import pandas as pd
import torch
from scipy.cluster.vq import kmeans2
from scipy.spatial import cKDTree

from lerobot_phantom.calibration.core import Param, fit_least_squares, seeded_split
from lerobot_phantom.calibration.projection import (
    CROSSTALK_NAMES,
    TripleProblem,
    nearest_surface_colour,
    projection_specs,
    tone_curve,
)

TENSOR = [f"A{c}{j}{k}" for c in range(3) for j in range(3) for k in range(3)]
TENSOR_FLOOR = [f"B{c}{j}" for c in range(3) for j in range(3)]
PRIMARY_WEIGHTS = [f"W{j}{k}" for j in range(3) for k in range(3)]
PRIMARY_FLOOR = [f"w{j}" for j in range(3)]


def stack(params, names, shape):
    return torch.stack([torch.as_tensor(params[n], dtype=torch.float64) for n in names]).reshape(shape)


class Forms:
    def __init__(self, problem: TripleProblem) -> None:
        self.p = problem

    def predict(self, form: str, effects, params, idx, added_only=False):
        s, q = self.p.surface[idx], self.p.projected[idx]
        decode, encode = tone_curve(effects, params)
        surf = decode(s)
        light = q.clamp(min=0) ** params["projector_gamma"] if form == "projector_curve" else decode(q)
        if form == "tensor":
            gain = torch.einsum("cjk,nk->ncj", stack(params, TENSOR, (3, 3, 3)), surf) + stack(
                params, TENSOR_FLOOR, (3, 3)
            )
            added = torch.einsum("ncj,nj->nc", gain, light)
        else:
            matrix = stack(params, CROSSTALK_NAMES, (3, 3))
            if form.startswith("primary_reflectance"):
                reflectance = surf @ stack(params, PRIMARY_WEIGHTS, (3, 3)).T + stack(
                    params, PRIMARY_FLOOR, (3,)
                )
                added = (light * reflectance) @ matrix.T
            elif "albedo_modulation" not in effects:
                added = light @ matrix.T
            else:
                reflectance = (surf + params["reflectance_floor"]).clamp(min=0)
                added = (
                    (light * reflectance) @ matrix.T
                    if form == "reflectance_first"
                    else (light @ matrix.T) * reflectance
                )
        total = surf + (0 if added_only == "none" else added)
        return encode(total).clamp(0, 1)

    def specs(self, form: str, effects):
        specs = projection_specs(effects)
        if form == "projector_curve":
            specs.append(Param("projector_gamma", 2.2, 0.3, 4.0, scale=1.0))
        if form == "tensor":
            specs = [s for s in specs if not s.name.startswith("crosstalk") and s.name != "reflectance_floor"]
            specs += [Param(n, 0.3 if n[1] == n[2] == n[3] else 0.0, -20, 20, scale=0.3) for n in TENSOR]
            specs += [Param(n, 0.0, -5, 5, scale=0.1) for n in TENSOR_FLOOR]
        if form.startswith("primary_reflectance"):
            # non-negative: a reflectance is a non-negative mix of what the surface returns in each channel
            low, floor_low = (0.0, -0.05) if form.endswith("non_negative") else (-10.0, -2.0)
            specs = [s for s in specs if s.name != "reflectance_floor"]
            specs += [Param(n, 1.0 if n[1] == n[2] else 0.0, low, 10, scale=0.3) for n in PRIMARY_WEIGHTS]
            specs += [Param(n, 0.1, floor_low, 5, scale=0.1) for n in PRIMARY_FLOOR]
        return specs

    def fit_and_score(self, form, effects, fit_items, heldout):
        f, h = torch.as_tensor(fit_items), torch.as_tensor(heldout)
        target = self.p.captured
        params = fit_least_squares(
            self.specs(form, effects),
            lambda pr: (self.predict(form, effects, pr, f) - target[f]).ravel(),
            tr_solver="exact",
            max_nfev=400,
        )
        with torch.no_grad():
            t = {k: torch.tensor(v) for k, v in params.items()}
            rmse = [
                float((255 * (self.predict(form, effects, t, i) - target[i])).pow(2).mean().sqrt())
                for i in (f, h)
            ]
        return params, rmse


def table_facts(path: Path, problem: TripleProblem, heldout: np.ndarray) -> None:
    """What the write-up quotes of the table itself: the spread of the pixels pooled into a row, how far apart in
    surface colour the held-out rows' nearest neighbours lie (the pairing of ``projection.nearest_surface_colour``),
    the surface colours' two k-means clusters, and the largest captured difference between two rows at most 1.5
    grey levels apart in surface colour under one projected colour."""
    table = pd.read_csv(path)
    spread = np.average(table["outcome_std"], weights=table["n_matching_pixels"])
    surface = problem.surface.numpy() * 255
    projected = np.round(problem.projected.numpy() * 255)
    captured = problem.captured.numpy() * 255
    nearest = nearest_surface_colour(surface[heldout], projected[heldout])
    paired = nearest >= 0
    distance = np.linalg.norm(surface[heldout][paired] - surface[heldout][nearest[paired]], axis=1)
    colours = np.unique(np.round(surface), axis=0)
    centres, label = kmeans2(colours, 2, seed=1, minit="++")
    print(
        f"  pooled pixels' spread (outcome_std weighted by n_matching_pixels) {spread:.2f}; held-out rows' nearest "
        f"neighbour {np.median(distance):.2f} grey levels apart (median); surface colours, 2-means: "
        + ", ".join(
            f"{np.round(c).astype(int).tolist()} ({n})"
            for c, n in zip(centres, np.bincount(label), strict=True)
        )
    )
    best = (0.0, None)
    for colour in np.unique(projected, axis=0):
        rows = np.flatnonzero(np.all(projected == colour, axis=1))
        for i, j in cKDTree(surface[rows]).query_pairs(1.5):
            gap = float(np.abs(captured[rows[i]] - captured[rows[j]]).max())
            if gap > best[0]:
                best = (gap, (colour, rows[i], rows[j]))
    colour, i, j = best[1]
    print(
        f"  largest captured difference within 1.5 grey levels of surface colour: {best[0]:.0f} under projected "
        f"{colour.astype(int).tolist()}: {np.round(surface[i]).astype(int).tolist()} -> "
        f"{np.round(captured[i]).astype(int).tolist()}, {np.round(surface[j]).astype(int).tolist()} -> "
        f"{np.round(captured[j]).astype(int).tolist()}"
    )


def main() -> None:
    path = Path(sys.argv[1])
    problem = TripleProblem(path)
    forms = Forms(problem)
    fit_items, heldout = seeded_split(problem.n_items, 0.2, 0)
    table_facts(path, problem, heldout)
    # the written models of both tables at bbe5bab (report.json): the bottle's has no reflectance term
    written = {"additive_light", "channel_crosstalk"} | (
        {"albedo_modulation"} if "stop_sign" in path.name else set()
    )
    written = frozenset(written)
    params, (fit_rmse, held_rmse) = forms.fit_and_score("written", written, fit_items, heldout)
    print(
        f"{path.name}: written model {sorted(written)}: fit {fit_rmse:.2f}, held-out {held_rmse:.2f} grey levels"
    )
    every = np.arange(problem.n_items)
    with torch.no_grad():
        t = {k: torch.tensor(v) for k, v in params.items()}
        predicted = forms.predict("written", written, t, torch.as_tensor(every)).numpy() * 255
        unlit = forms.predict("written", written, t, torch.as_tensor(every), added_only="none").numpy() * 255
    captured = problem.captured.numpy() * 255
    residual, added = predicted - captured, predicted - unlit
    surface = np.round(problem.surface.numpy() * 255).astype(int)
    projected = np.round(problem.projected.numpy() * 255).astype(int)
    surface_key = pd.Series([tuple(x) for x in surface])
    projected_key = np.array([hash(tuple(x)) for x in projected])
    r_held = residual[heldout]

    def held_rmse_after(prediction):
        return float(np.sqrt(np.mean((r_held - prediction) ** 2)))

    fit_frame = pd.DataFrame(residual[fit_items], columns=list("rgb"))
    fit_frame["key"] = surface_key[fit_items].to_numpy()
    means = fit_frame.groupby("key")[list("rgb")].mean()
    held_keys = surface_key[heldout].to_numpy()
    offset = np.nan_to_num(means.reindex(held_keys).to_numpy())
    lit = pd.DataFrame(added[fit_items], columns=list("rgb"))
    numerator = (fit_frame[list("rgb")] * lit.to_numpy()).groupby(fit_frame["key"]).sum().sum(axis=1)
    denominator = (lit**2).groupby(fit_frame["key"].to_numpy()).sum().sum(axis=1)
    strength = (numerator / denominator.replace(0, np.nan)).reindex(held_keys).fillna(0).to_numpy()
    print(
        f"  held-out rows whose surface colour has fit rows: {np.mean(np.isin(held_keys, means.index)):.2f}; "
        f"held-out RMSE after the fit rows' mean residual per surface colour {held_rmse_after(offset):.2f}, "
        f"after a strength of the added light per surface colour {held_rmse_after(strength[:, None] * added[heldout]):.2f}"
    )
    for k in (1, 5, 20):
        knn = np.zeros_like(r_held)
        for group in np.unique(projected_key):
            fit_in, held_in = (
                fit_items[projected_key[fit_items] == group],
                np.flatnonzero(projected_key[heldout] == group),
            )
            _, index = cKDTree(surface[fit_in]).query(surface[heldout][held_in], k=k)
            knn[held_in] = residual[fit_in][np.asarray(index).reshape(len(held_in), -1)].mean(axis=1)
        print(
            f"  after the mean residual of the {k} fit rows nearest in surface colour under the same projected colour: {held_rmse_after(knn):.2f}"
        )
    clear = (captured < 250) & (predicted < 250)
    lit_rows = projected.sum(axis=1) > 0
    per_row = np.where(clear, added * (captured - unlit), 0).sum(1) / np.maximum(
        np.where(clear, added**2, 0).sum(1), 1e-9
    )
    before = np.where(clear, captured - predicted, 0)[lit_rows]
    after = np.where(clear, captured - unlit - per_row[:, None] * added, 0)[lit_rows]
    count = clear[lit_rows].sum()
    print(
        f"  a strength of the added light per row, in sample, over unclipped values of lit rows: RMSE "
        f"{np.sqrt((before**2).sum() / count):.2f} -> {np.sqrt((after**2).sum() / count):.2f}; its 5/25/50/75/95% "
        f"quantiles {np.quantile(per_row[lit_rows], [0.05, 0.25, 0.5, 0.75, 0.95]).round(2).tolist()}"
    )
    for form, extra in (
        ("written", {"sensor_gamma"}),
        ("written", {"tone_shoulder"}),
        ("projector_curve", set()),
        ("projector_curve", {"sensor_gamma"}),
        ("reflectance_first", {"albedo_modulation"}),
        ("reflectance_first", {"albedo_modulation", "sensor_gamma"}),
        ("tensor", set()),
        ("tensor", {"sensor_gamma"}),
        ("primary_reflectance", {"albedo_modulation"}),
        ("primary_reflectance", {"albedo_modulation", "sensor_gamma"}),
        ("primary_reflectance_non_negative", {"albedo_modulation"}),
        ("primary_reflectance_non_negative", {"albedo_modulation", "sensor_gamma"}),
    ):
        effects = written | extra
        params, (fit_rmse, held_rmse) = forms.fit_and_score(form, effects, fit_items, heldout)
        shown = {
            k: round(v, 3)
            for k, v in params.items()
            if k in ("gamma", "projector_gamma", "reflectance_floor", "shoulder", "shoulder_exponent")
        }
        print(
            f"  {form} with {sorted(effects - written)}: fit {fit_rmse:.2f}, held-out {held_rmse:.2f} {shown}"
        )
        if form.startswith("primary_reflectance"):
            print(
                f"    reflectance weights per primary (rows) on the surface's channels: {np.array([params[n] for n in PRIMARY_WEIGHTS]).reshape(3, 3).round(2).tolist()}"
            )


if __name__ == "__main__":
    main()
