"""Frame pairs for the row-structured attacks: EM truncation and the laser color strip.

Both attacks act on whole sensor rows, and where in the frame they act is set by timing the attacker does not
report (when the interference hits the frame buffer, the laser's pulse phase). As for the EM color strip, that
placement is estimated from each frame itself, also for held-out frames; the fitted parameters are what the
frames share (colour gains, stripe geometry).
"""

from __future__ import annotations

import math

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param, fit_least_squares
from lerobot_phantom.calibration.frames import FrameProblem, Pair
from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.laser_color_strip import band_rows, strip_profile

# ---------------------------------------------------------------------------------------------------------------
# EM truncation

TRUNCATION_EFFECTS = (
    Effect(
        "free_band_position",
        "the interference corrupts the frame-buffer address at a moment set by the attacker's signal timing, not "
        "by how many rows are lost: the deleted band starts anywhere in the frame instead of at int(h * r)",
    ),
)


def truncation_source_rows(height: int, num: int, start: int) -> np.ndarray:
    """Source row of every output row when rows ``[start, start + num)`` are deleted and the tail is repeated."""
    rows = np.arange(height)
    shifted = (rows >= start) & (rows < height - num)
    return np.where(shifted, rows + num, rows)


def paper_start(height: int, num: int) -> int:
    """The paper's band start ``int(h r) = num``, clamped so the band never overlaps the appended tail (as
    ``transforms.em_truncation``)."""
    return max(0, min(num, height - 2 * num))


class TruncationFrames(FrameProblem):
    """Which rows were lost is read from each frame by an exhaustive search over integer row counts (and, with
    ``free_band_position``, band starts): the squared error of every (output row, source row) match is computed
    once per pair, so the search is exact and costs no fitting."""

    attack = "em_truncation"
    base_model = (
        "rows [int(h r), 2 int(h r)) deleted and the last int(h r) rows appended (the paper's EM truncation; the "
        "ratio r read from each frame by a search over integer row counts)"
    )
    extended_model = "EM truncation with a free band position"
    candidates = TRUNCATION_EFFECTS

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        self._placements: dict[tuple[bool, int], tuple[int, int]] = {}

    @staticmethod
    def match_costs(pair: Pair) -> np.ndarray:
        """``costs[i, j]``: squared error of predicting attacked row ``i`` by clean row ``j``."""
        attacked = pair.attacked.permute(1, 0, 2).reshape(pair.height, -1)
        clean = pair.clean.permute(1, 0, 2).reshape(pair.height, -1)
        return (torch.cdist(attacked, clean) ** 2).numpy()

    def placement(self, free_start: bool, index: int) -> tuple[int, int]:
        """(rows lost, band start) that best explain pair ``index``."""
        key = (free_start, index)
        if key not in self._placements:
            costs = self.match_costs(self.pairs[index])
            height = len(costs)
            rows = np.arange(height)
            same = np.concatenate([[0.0], np.cumsum(np.diag(costs))])  # rows kept in place
            best = (float(same[-1]), 0, 0)  # nothing lost
            for num in range(1, height // 2 + 1):
                moved = np.concatenate(
                    [[0.0], np.cumsum(costs[rows[: height - num], rows[: height - num] + num])]
                )
                starts = (
                    np.arange(0, height - 2 * num + 1) if free_start else np.array([paper_start(height, num)])
                )
                # rows < start stay, rows [start, h - num) move up by num, the last num rows repeat the tail
                total = same[starts] + (moved[height - num] - moved[starts]) + (same[-1] - same[height - num])
                k = int(np.argmin(total))
                if total[k] < best[0]:
                    best = (float(total[k]), num, int(starts[k]))
            self._placements[key] = (best[1], best[2])
        return self._placements[key]

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        num, start = self.placement("free_band_position" in fit.effects, index)
        pair = self.pairs[index]
        return pair.clean[:, torch.as_tensor(truncation_source_rows(pair.height, num, start))]

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        free = "free_band_position" in effects
        ratios, starts, strengths = [], [], []
        for i in items:
            num, band_start = self.placement(free, int(i))
            ratios.append(num / self.pairs[int(i)].height)
            starts.append(band_start / self.pairs[int(i)].height)
            strengths.append(self.pairs[int(i)].intensity)
        s, r = np.asarray(strengths), np.asarray(ratios)
        # the shared part: the ratio per unit of attack intensity (least squares through the origin)
        params = {
            "ratio_per_intensity": float((s * r).sum() / max((s * s).sum(), 1e-12)),
            "mean_ratio": float(r.mean()),
        }
        if free:
            params["mean_band_start_share"] = float(np.mean(starts))
        return Fit(effects, params)

    def transform_kwargs(self, fit: Fit) -> dict:
        """``EMTruncation`` keeps its intensity -> ratio table; a free band position is reported, not simulated."""
        return {}

    def derived(self, fit: Fit) -> dict:
        return {"ratio_at_intensity_1": fit.params["ratio_per_intensity"]}


# ---------------------------------------------------------------------------------------------------------------
# laser color strip

STRIP_EFFECTS = (
    Effect(
        "exposure_overlap",
        "a rolling shutter exposes each row during its own time window, so a laser pulse lights every row whose "
        "window overlaps the pulse: a stripe across the whole width, (pulse on-time + exposure) / row time rows "
        "tall with ramps at its edges, wherever the pulse falls in the frame - not a fixed Gaussian band",
    ),
    Effect(
        "stripe_period",
        "the laser pulses again before the frame is read out, so the stripe repeats every "
        "1 / (laser frequency x row time) rows",
        requires=("exposure_overlap",),
    ),
)
SINGLE_PULSE_PERIOD = 4.0  # frame heights: a pulse train this slow puts at most one stripe in any frame
PHASE_STEP_ROWS = 1.0


class StripFrames(FrameProblem):
    """Base: the paper's band (rows h//3 .. 2 (h//3), Gaussian-weighted), colour gains fitted. With
    ``exposure_overlap``: ``physics.rolling_shutter_row_light`` in units of frame heights (row time = 1 / h), the
    pulse's on-time and the exposure fitted, its phase read from each frame; ``stripe_period`` fits the pulse
    period too. Light scales with the pair's intensity."""

    attack = "laser_color_strip"
    base_model = "the paper's fixed Gaussian-weighted band (rows h/3 to 2h/3), per-channel strength fitted"
    extended_model = "rolling-shutter stripe (rows lit by pulse/exposure overlap)"
    candidates = STRIP_EFFECTS

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        self.profiles = []
        for pair in pairs:
            start, end = band_rows(pair.height)
            full = torch.zeros(pair.height, pair.width, dtype=torch.float64)
            full[start:end] = strip_profile(pair.height, pair.width).double() / 255.0
            self.profiles.append(full)

    # -- the paper's band
    def predict_band(self, params, index: int) -> torch.Tensor:
        pair = self.pairs[index]
        gains = torch.stack([params["strength_r"], params["strength_g"], params["strength_b"]]).reshape(
            3, 1, 1
        )
        return (pair.clean + pair.intensity * gains * self.profiles[index]).clamp(0.0, 1.0)

    # -- the rolling-shutter stripe
    @staticmethod
    def row_light(params, height: int, phase_rows: torch.Tensor) -> torch.Tensor:
        """(B, H) lit fraction of every row for the pulse phases ``phase_rows`` (in rows)."""
        period = params.get("period_share", SINGLE_PULSE_PERIOD)
        period = torch.as_tensor(period, dtype=torch.float64)
        on = torch.as_tensor(params["on_share"], dtype=torch.float64)
        return physics.rolling_shutter_row_light(
            height,
            1.0 / period,
            (on / period).clamp(max=1.0),
            params["exposure_share"],
            1.0 / height,
            phase_s=phase_rows / height,
            dtype=torch.float64,
        )

    def stripe_gains(self, params) -> torch.Tensor:
        return torch.stack([torch.as_tensor(params[f"peak_{c}"], dtype=torch.float64) for c in "rgb"])

    def predict_stripe(self, params, index: int, phase_rows) -> torch.Tensor:
        pair = self.pairs[index]
        light = self.row_light(params, pair.height, torch.as_tensor(phase_rows, dtype=torch.float64))[0]
        added = pair.intensity * self.stripe_gains(params).reshape(3, 1, 1) * light.reshape(1, -1, 1)
        return (pair.clean + added).clamp(0.0, 1.0)

    def best_phase(self, params, index: int) -> float:
        """The pulse phase (rows) that best explains pair ``index``: a grid search over every stripe position."""
        pair = self.pairs[index]
        height = pair.height
        if "period_share" in params:
            span = (0.0, float(params["period_share"]) * height)
        else:
            # row r sees the pulse when r + phase lies in [-exposure, on]: phases -h .. stripe height cover all
            span = (-float(height), (float(params["on_share"]) + float(params["exposure_share"])) * height)
        phases = torch.arange(span[0], span[1], PHASE_STEP_ROWS, dtype=torch.float64)
        with torch.no_grad():
            light = self.row_light(params, height, phases)  # (P, H)
            gains = pair.intensity * self.stripe_gains(params).reshape(1, 3, 1, 1)
            predicted = (pair.clean.unsqueeze(0) + gains * light[:, None, :, None]).clamp(0.0, 1.0)
            cost = ((predicted - pair.attacked.unsqueeze(0)) ** 2).sum(dim=(1, 2, 3))
        return float(phases[int(torch.argmin(cost))])

    def predict_pair(self, fit: Fit, index: int) -> torch.Tensor:
        with torch.no_grad():
            if "exposure_overlap" not in fit.effects:
                params = {k: torch.as_tensor(v, dtype=torch.float64) for k, v in fit.params.items()}
                return self.predict_band(params, index)
            return self.predict_stripe(fit.params, index, self.best_phase(fit.params, index))

    def initial_stripe(self, items: np.ndarray) -> dict[str, float]:
        """Start values read from the data: the brightest row's colour and the lit band's height."""
        peaks, widths = [], []
        for i in items:
            pair = self.pairs[int(i)]
            rows = (pair.attacked - pair.clean).mean(dim=2) / max(pair.intensity, 1e-3)  # (3, H)
            total = rows.sum(0)
            peaks.append(rows[:, int(torch.argmax(total))].clamp(min=0.0).numpy())
            widths.append(float((total > 0.5 * total.max()).double().mean()))
        width = max(float(np.median(widths)), 2.0 / min(p.height for p in self.pairs))
        peak = np.median(np.stack(peaks), axis=0)
        return {
            "peak_r": float(peak[0]),
            "peak_g": float(peak[1]),
            "peak_b": float(peak[2]),
            "on_share": 0.6 * width,
            "exposure_share": 0.4 * width,
        }

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        if "exposure_overlap" not in effects:
            band = [Param(f"strength_{c}", 500.0, 0.0, 20000.0, scale=500.0) for c in "rgb"]
            params = fit_least_squares(
                band,
                lambda p: torch.cat(
                    [(self.predict_band(p, int(i)) - self.pairs[int(i)].attacked).ravel() for i in items]
                ),
            )
            return Fit(effects, params)
        specs = [Param(f"peak_{c}", 0.3, 0.0, 4.0, scale=0.3) for c in "rgb"] + [
            Param("on_share", 0.1, 1e-3, 1.0, scale=0.1),
            Param("exposure_share", 0.05, 0.0, 1.0, scale=0.1),
        ]
        starts = [self.initial_stripe(items)]
        if "stripe_period" in effects:
            specs.append(Param("period_share", 0.5, 0.05, 2.0, scale=0.3))
            shares = (0.25, 0.4, 0.6)
            starts = [{**starts[0], "period_share": share} for share in shares]
        if start is not None and "exposure_overlap" in start.effects:
            starts.insert(0, {**starts[0], **start.params})
        best: tuple[float, dict] | None = None
        for params in starts:
            for _ in range(2):  # alternate: phases given the stripe, stripe given the phases
                phases = {int(i): self.best_phase(params, int(i)) for i in items}

                def residuals(p, phases=phases):
                    return torch.cat(
                        [
                            (
                                self.predict_stripe(p, int(i), phases[int(i)]) - self.pairs[int(i)].attacked
                            ).ravel()
                            for i in items
                        ]
                    )

                params = fit_least_squares(specs, residuals, warm=params, autodiff=False, max_nfev=25)
            cost = sum(
                float(
                    (
                        (
                            self.predict_stripe(params, int(i), self.best_phase(params, int(i)))
                            - self.pairs[int(i)].attacked
                        )
                        ** 2
                    ).sum()
                )
                for i in items
            )
            if best is None or cost < best[0]:
                best = (cost, params)
        assert best is not None
        return Fit(effects, best[1])

    def transform_kwargs(self, fit: Fit) -> dict:
        """``LaserColorStrip`` options: the colour split of the fitted light; with ``exposure_overlap`` the
        rolling-shutter model on a 720-row frame (frame time 1 s scaled away: only shares of the frame matter)."""
        p = fit.params
        if "exposure_overlap" not in fit.effects:
            total = p["strength_r"] + p["strength_g"] + p["strength_b"]
            fractions = [p[f"strength_{c}"] / max(total, 1e-12) for c in "rgb"]
            return {"color_fractions": fractions, "levels": [0.0, total / 3, 2 * total / 3, total]}
        peaks = [p[f"peak_{c}"] for c in "rgb"]
        top = max(max(peaks), 1e-12)
        # one pulse per frame when no period was measured: the stripe lands somewhere in every frame
        period = p.get("period_share", 1.0)
        strength = top * 255.0 * math.pi / 4.0  # the transform's peak gain is 4 S / pi grey levels
        return {
            "model": "rolling_shutter",
            "color_fractions": [min(v / top, 1.0) for v in peaks],
            "levels": [0.0, strength / 3, 2 * strength / 3, strength],
            "frequency_hz": 1.0 / period,
            "duty": min(p["on_share"] / period, 1.0),
            "exposure_s": p["exposure_share"],
            "row_time_s": 1.0 / 720,
            "frame_rows": 720,
        }

    def derived(self, fit: Fit) -> dict:
        p = fit.params
        if "exposure_overlap" not in fit.effects:
            return {}
        out = {"stripe_rows_share": p["on_share"] + p["exposure_share"]}
        if "period_share" in p:
            out["stripe_period_share"] = p["period_share"]
        return out


ROW_FRAME_PROBLEMS = {"em_truncation": TruncationFrames, "laser_color_strip": StripFrames}
