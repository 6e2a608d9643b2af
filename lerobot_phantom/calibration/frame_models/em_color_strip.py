"""EM color strip frame pairs: rows decoded through the wrong colour map by electromagnetic interference."""

from __future__ import annotations

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param, fit_least_squares
from lerobot_phantom.calibration.frame_models.common import LatentFrameProblem
from lerobot_phantom.calibration.noise import NoiseSources
from lerobot_phantom.transforms import physics

EM_EFFECTS = (
    Effect(
        "bayer_phase_flip",
        "interference drops an odd number of rows from the video stream; every later row is then demosaiced with "
        "the colour-filter phase off by one, so the wrong colours run from that row to the frame's end instead "
        "of alternating in periodic bands",
    ),
    Effect(
        "bayer_demosaic",
        "a lost line moves the later raw lines up by one, so the ISP interpolates each mis-decoded row's colours "
        "from the next row's samples on the wrong colour sites (a bilinear demosaic of the Bayer mosaic, colour "
        "filter tile fitted): red and blue from its neighbours' green, green alternating between red and blue "
        "samples, with colour fringes at edges, not the paper's colour map of each pixel",
    ),
)


class EMStripFrames(LatentFrameProblem):
    """Rows are either decoded correctly or through the wrong colour map. Where they go wrong (the bands' phase,
    the flip row) is set by when the interference hits: registered on fit frames, and for held-out frames
    marginalised over a uniform prior (every phase of the fitted period, every flip row)."""

    attack = "em_color_strip"
    base_model = (
        "periodic bands of mis-decoded colour (the paper's EM color strip; period, phase, colour fitted)"
    )
    extended_model = "Bayer phase flip"
    candidates = EM_EFFECTS
    periods = tuple(np.linspace(0.04, 1.0, 49))  # band period as a share of the frame height
    latent = "band phase or flip row of each frame (when the interference hits)"

    def __init__(self, pairs, seed: int) -> None:
        super().__init__(pairs, seed)
        self._line_terms: dict[tuple[int, str], tuple[torch.Tensor, torch.Tensor]] = {}

    def line_terms(self, index: int, pattern: str) -> tuple[torch.Tensor, torch.Tensor]:
        """``physics.bayer_line_terms`` of pair ``index``'s clean frame with tile ``pattern`` (fixed by the frame,
        so computed once)."""
        key = (index, pattern)
        if key not in self._line_terms:
            self._line_terms[key] = physics.bayer_line_terms(self.pairs[index].clean.unsqueeze(0), pattern)
        return self._line_terms[key]

    def colour_mapped(self, params, index: int, rows=slice(None)) -> torch.Tensor:
        """Pair ``index``'s ``rows`` through the paper's colour map of each pixel (with the fitted gain, offset)."""
        clean = self.pairs[index].clean[:, rows].unsqueeze(0)
        return physics.em_color_map(clean, params["gain"], params["offset"])[0]

    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        specs = [Param("gain", 2.5, 0.0, 10.0), Param("offset", 50.0 / 255.0, -1.0, 1.0, 0.1)]
        if "bayer_phase_flip" not in effects:
            specs.append(Param("period", 0.25, self.periods[0], self.periods[-1]))
        return specs

    @staticmethod
    def placement_sse(costs, masks: np.ndarray) -> np.ndarray:
        """SSE of each placement (``masks`` ``(K, H)``, the rows it mis-decodes) from ``row_costs``: a row's own
        cost, or with ``bayer_demosaic`` the cost of its neighbourhood (the line above, its own, the line below
        moved or not; mirrored at the frame's border, as the demosaic is)."""
        if isinstance(costs, tuple):
            keep, swap = costs
            return np.where(masks, swap[None, :], keep[None, :]).sum(1)
        moved = np.pad(masks, ((0, 0), (1, 1)), mode="reflect").astype(np.int64)
        neighbourhood = 4 * moved[:, :-2] + 2 * moved[:, 1:-1] + moved[:, 2:]
        return costs[neighbourhood, np.arange(masks.shape[1])[None, :]].sum(1)

    @classmethod
    def band_phase_costs(cls, costs, period_rows: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(phases, SSE for each, prior weight of each): one phase inside every interval of phases over which
        the band mask stays the same (its edges cross a row at ``r mod P`` and ``(r - P/2) mod P``), weighted
        by the interval's share of the period - every distinct band placement, exactly, under a uniform phase."""
        rows = np.arange(costs[0].shape[-1])
        edges = np.unique(
            np.concatenate([rows % period_rows, (rows - 0.5 * period_rows) % period_rows, [0.0]])
        )
        bounds = np.append(edges, period_rows)
        phases = 0.5 * (bounds[:-1] + bounds[1:])
        weights = np.diff(bounds) / period_rows
        masks = np.remainder(rows[None, :] - phases[:, None], period_rows) < 0.5 * period_rows
        return phases, cls.placement_sse(costs, masks), weights

    @classmethod
    def flip_row_costs(cls, costs) -> np.ndarray:
        """SSE when rows from ``start`` on are flipped, for every start 0..h."""
        if isinstance(costs, tuple):
            keep, swap = costs
            return np.concatenate([[0.0], np.cumsum(keep)]) + np.concatenate(
                [np.cumsum(swap[::-1])[::-1], [0.0]]
            )
        height = costs.shape[1]
        return cls.placement_sse(costs, np.arange(height)[None, :] >= np.arange(height + 1)[:, None])

    def latent_candidates(self, fit: Fit, index: int) -> tuple[np.ndarray, np.ndarray]:
        costs = self.row_costs(fit.effects, fit.params, index, fit.extra.get("pattern"))
        if "bayer_phase_flip" in fit.effects:
            sse = self.flip_row_costs(costs)
        else:
            _, sse, weights = self.band_phase_costs(costs, fit.params["period"] * self.pairs[index].height)
            return sse, weights
        return sse, np.full(len(sse), 1.0 / len(sse))

    def row_costs(self, effects, params, index: int, pattern: str | None):
        """Each row's SSE: under the colour map ``(keep, swap)``, the row as it is or mapped; with
        ``bayer_demosaic`` an ``(8, H)`` array, one per neighbourhood ``4 above + 2 own + below`` (1: that raw
        line moved up), since a row's interpolation reads the lines beside it: a mis-decoded row shows the map's
        colours on the demosaic of its neighbourhood, a row left as it is keeps its colours plus what a moved
        neighbouring line adds."""
        pair = self.pairs[index]
        keep = ((pair.attacked - pair.clean) ** 2).sum(dim=(0, 2)).numpy()
        if "bayer_demosaic" not in effects:
            swap = ((pair.attacked - self.colour_mapped(params, index)) ** 2).sum(dim=(0, 2))
            return keep, swap.numpy()
        terms, weights = self.line_terms(index, pattern)
        before = (terms[0, 0] + terms[0, 1] + terms[0, 2]) / weights
        costs = []
        for neighbourhood in range(8):
            above, own, below = (neighbourhood >> 2) & 1, (neighbourhood >> 1) & 1, neighbourhood & 1
            after = (terms[above, 0] + terms[own, 1] + terms[below, 2]) / weights
            if own:
                shown = physics.em_colours_of_demosaic(after, params["gain"], params["offset"])[0]
            else:
                shown = pair.clean + (after - before)[0]
            costs.append(((pair.attacked - shown) ** 2).sum(dim=(0, 2)).numpy())
        return np.stack(costs)

    @classmethod
    def best_band_phase(cls, costs, period_rows: float) -> tuple[float, float]:
        phases, sse, _ = cls.band_phase_costs(costs, period_rows)
        k = int(np.argmin(sse))
        return float(sse[k]), float(phases[k])

    @classmethod
    def best_flip_row(cls, costs) -> tuple[float, int]:
        sse = cls.flip_row_costs(costs)
        start = int(np.argmin(sse))
        return float(sse[start]), start

    def placements(self, effects, params, items, pattern: str | None = None) -> dict[int, tuple[str, float]]:
        """Per-frame placement (band phase or flip row) registered on each frame: fit frames, figures."""
        out = {}
        for i in items:
            costs = self.row_costs(effects, params, int(i), pattern)
            if "bayer_phase_flip" in effects:
                out[int(i)] = ("flip", float(self.best_flip_row(costs)[1]))
            else:
                period = params["period"] * self.pairs[int(i)].height
                out[int(i)] = ("bands", self.best_band_phase(costs, period)[1])
        return out

    def mask(self, effects, params, index: int, placement) -> torch.Tensor:
        height = self.pairs[index].height
        kind, value = placement
        if kind == "flip":
            return physics.bayer_flip_mask(height, value)[0].double()
        return physics.periodic_band_mask(height, params["period"] * height, value)[0].double()

    def predict_registered(self, fit: Fit, index: int) -> torch.Tensor:
        pattern = fit.extra.get("pattern")
        placement = self.placements(fit.effects, fit.params, [index], pattern)[index]
        pair = self.pairs[index]
        mask = self.mask(fit.effects, fit.params, index, placement)
        if "bayer_demosaic" in fit.effects:
            terms, weights = self.line_terms(index, pattern)
            moved = mask[:, :, 0]
            gain, offset = fit.params["gain"], fit.params["offset"]
            return physics.em_demosaic_rows(terms, weights, pair.clean.unsqueeze(0), moved, gain, offset)[0]
        mapped = self.colour_mapped(fit.params, index)
        return mask * mapped + (1 - mask) * pair.clean

    def noise_sources(self, fit: Fit, index: int) -> NoiseSources:
        """Interference corrupts the decoding, after the sensor: a mis-decoded row's red and blue are its sensor
        green times the map's gain, its green the mean of its sensor red and blue, and they carry those values'
        noise so scaled (the paper's gain 2.5: 6.25 times the variance, read at green's signal, not at the brighter
        value shown). The clean frame the prediction maps carries its noise the same way. With ``bayer_demosaic``
        the same weights stand for the interpolated samples (not traced: an interpolation of two to four samples
        carries less of their noise, and the clean frame's own demosaic already averaged it)."""
        pair = self.pairs[index]
        placement = self.placements(fit.effects, fit.params, [index], fit.extra.get("pattern"))[index]
        rows = self.mask(fit.effects, fit.params, index, placement)[0, :, 0].bool().numpy()
        clean = 255.0 * pair.clean.numpy()
        first, first_weight = clean.copy(), np.ones_like(clean)
        second, second_weight = clean.copy(), np.zeros_like(clean)
        first[0, rows] = first[2, rows] = clean[1, rows]
        first[1, rows] = clean[0, rows]
        first_weight[0, rows] = first_weight[2, rows] = fit.params["gain"]
        first_weight[1, rows] = second_weight[1, rows] = 0.5
        second[1, rows] = clean[2, rows]
        return (first, first_weight), (second, second_weight)

    # Colour maps the alternating fit starts from: the paper's, and the one demosaicing with the colour-filter
    # phase off by one gives (green read as red and blue, their mean as green: gain 1, offset 0). The map is
    # clamped to [0, 1], so wherever gain x G saturates the error is flat in the gain: started from one map alone
    # the fit can stay at it (seen: gain held at 2.5 with offset -0.69, painting the bands white on a bright,
    # filmic camera), and the bands are then placed by a wrong colour.
    COLOUR_STARTS = ({"gain": 2.5, "offset": 50.0 / 255.0}, {"gain": 1.0, "offset": 0.0})

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        if start is not None and start.effects == effects:
            # a refit of the same model (bootstrap draws): the colour-filter tile too is the estimate's
            return self._fit_from(effects, items, dict(start.params), start.extra.get("pattern"), rounds=1)
        # the tile is a property of the sensor, one of four: each is fitted and the fit items choose
        patterns = tuple(physics.BAYER_PATTERNS) if "bayer_demosaic" in effects else (None,)
        fits = [
            self._fit_from(effects, items, {**colour, "period": 0.25}, pattern, rounds=3)
            for pattern in patterns
            for colour in self.COLOUR_STARTS
        ]
        return min(fits, key=lambda fit: fit.extra["noise_variance"])  # the registered SSE over ``items``

    def _fit_from(
        self, effects: frozenset[str], items: np.ndarray, params: dict, pattern: str | None, rounds: int
    ) -> Fit:
        """Alternate ``rounds`` times: placement given the colour map, colour map given the placement."""
        for _ in range(rounds):
            if "bayer_phase_flip" not in effects:
                row_costs = [self.row_costs(effects, params, int(i), pattern) for i in items]

                def total(period, row_costs=row_costs):
                    return sum(
                        self.best_band_phase(costs, period * self.pairs[int(i)].height)[0]
                        for i, costs in zip(items, row_costs, strict=True)
                    )

                coarse = min(self.periods, key=total)
                step = self.periods[1] - self.periods[0]
                fine = np.linspace(
                    max(coarse - step, self.periods[0]), min(coarse + step, self.periods[-1]), 11
                )
                params["period"] = float(min(fine, key=total))
            placement = self.placements(effects, params, items, pattern)
            masks = {
                int(i): self.mask(effects, params, int(i), placement[int(i)])[0, :, 0].bool() for i in items
            }
            # with the demosaic, the mis-decoded rows' interpolation given the placement (the colours are fitted on it)
            moved_lines = {
                i: physics.demosaic_of_moved_lines(*self.line_terms(i, pattern), rows[None].double())[
                    :, :, rows
                ]
                for i, rows in masks.items()
                if "bayer_demosaic" in effects and rows.any()
            }

            def residuals(p, masks=masks, moved_lines=moved_lines):
                parts = []
                for i in items:
                    rows = masks[int(i)]
                    if not rows.any():
                        continue
                    if "bayer_demosaic" in effects:
                        shown = physics.em_colours_of_demosaic(moved_lines[int(i)], p["gain"], p["offset"])[0]
                    else:
                        shown = self.colour_mapped(p, int(i), rows)
                    parts.append((shown - self.pairs[int(i)].attacked[:, rows]).ravel())
                return torch.cat(parts) if parts else torch.zeros(1, dtype=torch.float64)

            colour = fit_least_squares(
                [Param("gain", params["gain"], 0.0, 10.0), Param("offset", params["offset"], -1.0, 1.0, 0.1)],
                residuals,
            )
            params.update(colour)
        if "bayer_phase_flip" in effects:
            params.pop("period", None)
        fit = Fit(effects, params, {} if pattern is None else {"pattern": pattern})
        fit.extra["noise_variance"] = self.noise_variance(fit, items)
        return fit

    def derived(self, fit: Fit) -> dict:
        return {"colour_filter_tile": fit.extra["pattern"]} if "bayer_demosaic" in fit.effects else {}

    def transform_kwargs(self, fit: Fit) -> dict:
        """``EMColorStrip`` options: the fitted colour map, the Bayer-flip model where it was found, and with
        ``bayer_demosaic`` the demosaic's tile. The paper's bands keep the attack's stripe count per intensity (the
        fitted period is not an option: it would leave the intensity nothing to set)."""
        demosaic = {"demosaic_pattern": fit.extra["pattern"]} if "bayer_demosaic" in fit.effects else {}
        colours = {"gain": fit.params["gain"], "offset": fit.params["offset"]}
        model = {"model": "bayer_phase_flip"} if "bayer_phase_flip" in fit.effects else {}
        return {**model, **colours, **demosaic}
