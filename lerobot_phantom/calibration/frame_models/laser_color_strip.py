"""Laser color strip frame pairs: the rows a pulsed laser lights in a rolling-shutter camera."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param, fit_least_squares
from lerobot_phantom.calibration.frame_models.common import (
    SENSOR_GAMMA,
    LatentFrameProblem,
    Pair,
    ParameterMemo,
    parameter_values,
)
from lerobot_phantom.calibration.tone import (
    GAMMA_PARAM,
    SHOULDER_PARAMS,
    TONE_PARAMS,
    decode_encode,
    implied_gamma_statistic,
    shoulder_kwargs,
    tone_nulls,
)
from lerobot_phantom.transforms import physics
from lerobot_phantom.transforms.laser_color_strip import band_rows, strip_profile

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
    # the paper's band is a recipe in grey levels with no amount of light behind it; the tone curve acts on the
    # light the stripe model measures (pulse x exposure overlap), so it builds on that model
    dataclasses.replace(SENSOR_GAMMA, requires=("exposure_overlap",)),
    Effect(
        "tone_shoulder",
        "the camera's tone curve rolls off towards white (a filmic / log-logistic shoulder, calibration/tone.py): "
        "the stripe's light, added in linear irradiance, brightens bright surfaces far less than a power law "
        "predicts, so one stripe's grey levels change with the scene behind it",
        requires=("exposure_overlap",),
        excludes=("sensor_gamma",),
        # a shouldered curve decodes pixels to linear light as the power law does (tone.py): it is a gamma
        # encoding too, judged by its equivalent power-law gamma
        implies=("sensor_gamma",),
    ),
)
SINGLE_PULSE_PERIOD = 4.0  # frame heights: a pulse train this slow puts at most one stripe in any frame
PHASE_STEP_ROWS = 1.0
PERIOD_SCAN = (0.05, 2.0)  # frame heights: the period's search range
PERIOD_SCAN_STEPS = 48
PERIOD_STARTS = 3
STRIPE_SHARES_OF_PERIOD = (0.3, 0.5, 0.7)
TONE_EFFECTS = frozenset({"sensor_gamma", "tone_shoulder"})
# a clean frame decoded and re-encoded under the tone curve, kept for each pair at the fitted point and at a step of
# each tone parameter (finite-difference Jacobian columns that move another parameter repeat it)
TONE_MEMO_PER_PAIR = 2 * (1 + len(TONE_PARAMS))
ON_SHARES_OF_STRIPE = (0.2, 0.5, 0.8)  # single-stripe starts: the pulse's share of the stripe's rows


class StripFrames(LatentFrameProblem):
    """Base: the paper's band (rows h//3 .. 2 (h//3), Gaussian-weighted), colour gains fitted. With
    ``exposure_overlap``: ``physics.rolling_shutter_row_light`` in units of frame heights (row time = 1 / h), the
    pulse's on-time and the exposure fitted; ``stripe_period`` fits the pulse period too. Light scales with the
    pair's intensity. The laser is not synchronised with the camera, so the pulse phase is registered on fit
    frames and, for held-out frames, marginalised over a uniform prior (every stripe position).

    With ``sensor_gamma`` the laser's light adds to the scene's in linear irradiance, before the camera's tone
    curve (a power law ``x ** gamma`` decodes the pixels): a stripe brightens dark surfaces by more grey levels
    than bright ones, and saturates at the sensor's full well. ``tone_shoulder`` decodes through a curve that
    rolls off towards white instead (calibration/tone.py), a form no power law takes: fitted to a filmic camera,
    the power law's exponent ran to its bound (independent simulator, strip_period case,
    docs/bench/camsim_session25.md)."""

    attack = "laser_color_strip"
    base_model = "the paper's fixed Gaussian-weighted band (rows h/3 to 2h/3), per-channel strength fitted"
    extended_model = "rolling-shutter stripe (rows lit by pulse/exposure overlap)"
    candidates = STRIP_EFFECTS
    latent = "pulse phase of each frame (the laser is not synchronised with the camera)"

    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        if "exposure_overlap" not in effects:
            return [Param(f"strength_{c}", 500.0, 0.0, 20000.0, scale=500.0) for c in "rgb"]
        # a laser is nearly monochromatic: a channel whose colour filter blocks its wavelength records almost
        # none of it, so a peak at 0 is that channel's physical limit, not an edge of the search
        specs = [
            Param(
                f"peak_{c}",
                0.3,
                0.0,
                4.0,
                scale=0.3,
                low_limit="a channel whose colour filter passes none of the laser's light",
            )
            for c in "rgb"
        ] + [
            Param("on_share", 0.1, 1e-3, 1.0, scale=0.1),
            Param("exposure_share", 0.05, 0.0, 1.0, scale=0.1),
        ]
        if "stripe_period" in effects:
            specs.append(Param("period_share", 0.5, 0.05, 2.0, scale=0.3))
        if "sensor_gamma" in effects:
            specs.append(GAMMA_PARAM)
        if "tone_shoulder" in effects:
            specs += list(SHOULDER_PARAMS)
        return specs

    def null_values(self, effect: str) -> dict[str, float]:
        return tone_nulls(effect)  # the stripe adds to the encoded values

    def implied_statistic(
        self, effect: str, implied: str, params: dict[str, float]
    ) -> tuple[str, float, float]:
        return implied_gamma_statistic(effect, implied, params)

    def __init__(self, pairs: list[Pair], seed: int) -> None:
        super().__init__(pairs, seed)
        self.profiles = []
        for pair in pairs:
            start, end = band_rows(pair.height)
            full = torch.zeros(pair.height, pair.width, dtype=torch.float64)
            full[start:end] = strip_profile(pair.height, pair.width).double() / 255.0
            self.profiles.append(full)
        self._period_starts: dict[frozenset[str], list[dict[str, float]]] = {}
        self.tone_memo = ParameterMemo(TONE_MEMO_PER_PAIR * len(pairs))

    # -- the paper's band
    def predict_band(self, params, index: int) -> torch.Tensor:
        pair = self.pairs[index]
        gains = torch.stack([params["strength_r"], params["strength_g"], params["strength_b"]]).reshape(
            3, 1, 1
        )
        return (pair.clean + pair.intensity * gains * self.profiles[index]).clamp(0.0, 1.0)

    # -- the rolling-shutter stripe
    @staticmethod
    def row_light(params, height, phase_rows: torch.Tensor, rows: int | None = None) -> torch.Tensor:
        """(B, rows) lit fraction of every row for the pulse phases ``phase_rows`` (in rows) of frames ``height``
        rows tall (a number, or one per phase); ``rows`` defaults to ``height``."""
        period = params.get("period_share", SINGLE_PULSE_PERIOD)
        period = torch.as_tensor(period, dtype=torch.float64)
        on = torch.as_tensor(params["on_share"], dtype=torch.float64)
        return physics.rolling_shutter_row_light(
            height if rows is None else rows,
            1.0 / period,
            (on / period).clamp(max=1.0),
            params["exposure_share"],
            1.0 / height,
            phase_s=phase_rows / height,
            dtype=torch.float64,
        )

    def stripe_gains(self, params) -> torch.Tensor:
        return torch.stack([torch.as_tensor(params[f"peak_{c}"], dtype=torch.float64) for c in "rgb"])

    @staticmethod
    def tone(params):
        """(decode, encode) between pixel values and the light the stripe adds to: the fitted shoulder, the
        ``sensor_gamma`` power law, or the encoded values themselves; light beyond the full well is clipped."""
        return decode_encode(
            params, "shoulder" in params, None if "shoulder" in params else params.get("gamma", 1.0)
        )

    def unlit_frame(self, params, index: int) -> tuple[torch.Tensor, torch.Tensor]:
        """Pair ``index``'s clean frame decoded under the model's tone curve, and re-encoded: what every row no
        pulse reaches is predicted to hold."""
        pair = self.pairs[index]

        def decoded_and_encoded():
            decode, encode = self.tone(params)
            linear = decode(pair.clean)
            return torch.stack([linear, encode(linear)])

        frames = self.tone_memo.get(
            pair.clean, lambda: parameter_values(params, TONE_PARAMS), decoded_and_encoded
        )
        return frames[0], frames[1]

    def predict_stripe(
        self, params, index: int, phase_rows, light: torch.Tensor | None = None
    ) -> torch.Tensor:
        """Pair ``index``'s attacked frame with the pulse at ``phase_rows``; ``light``: its rows' lit fractions at
        that phase, when already computed (``predict_stripes``)."""
        pair = self.pairs[index]
        if light is None:
            light = self.row_light(params, pair.height, torch.as_tensor(phase_rows, dtype=torch.float64))[0]
        added = pair.intensity * self.stripe_gains(params).reshape(3, 1, 1) * light.reshape(1, -1, 1)
        _, encode = self.tone(params)
        # a stripe lights a share of the rows: the tone curve runs over those, the others hold the unlit frame
        linear, unlit = self.unlit_frame(params, index)
        rows = torch.nonzero(light).flatten()
        predicted = unlit.clone()
        predicted[:, rows] = encode(linear[:, rows] + added[:, rows])
        return predicted

    def predict_stripes(self, params, items: np.ndarray, phase_rows: dict[int, float]) -> list[torch.Tensor]:
        """``predict_stripe`` of every pair of ``items`` at its phase, their row light from one call over the
        tallest frame's rows. A row's light depends on its frame's row time and phase alone, so each frame's rows
        hold, to the bit, what a call for that frame alone gives (the kit's frames have distinct heights)."""
        heights = [self.pairs[int(i)].height for i in items]
        light = self.row_light(
            params,
            torch.tensor(heights, dtype=torch.float64),
            torch.tensor([float(phase_rows[int(i)]) for i in items], dtype=torch.float64),
            rows=max(heights),
        )
        return [
            self.predict_stripe(params, int(i), phase_rows[int(i)], light[k, :height])
            for k, (i, height) in enumerate(zip(items, heights, strict=True))
        ]

    def phase_costs(self, params, index: int) -> tuple[torch.Tensor, np.ndarray]:
        """(pulse phases in rows, SSE of pair ``index`` for each): every stripe position, a row apart."""
        pair = self.pairs[index]
        height = pair.height
        if "period_share" in params:
            span = (0.0, float(params["period_share"]) * height)
        else:
            # row r integrates over [r + phase, r + phase + exposure] (rows) and the pulse is on over [0, on]: some
            # row of the frame is lit exactly for phases in (-(h - 1) - exposure, on); whole rows from the first
            exposure_rows = float(params["exposure_share"]) * height
            span = (math.ceil(-(height - 1) - exposure_rows), float(params["on_share"]) * height)
        phases = torch.arange(span[0], span[1], PHASE_STEP_ROWS, dtype=torch.float64)
        with torch.no_grad():
            light = self.row_light(params, height, phases)  # (P, H)
            _, encode = self.tone(params)
            linear, unlit_frame = self.unlit_frame(params, index)
            # a row no pulse reaches costs the same at every phase: the tone curve runs only over the lit rows of
            # each phase (a stripe covers a share of the frame), the rest is each row's unlit cost
            unlit = ((unlit_frame - pair.attacked) ** 2).sum(dim=(0, 2))  # (H,)
            phase_of, row_of = torch.nonzero(light, as_tuple=True)
            gains = pair.intensity * self.stripe_gains(params).reshape(3, 1, 1)
            predicted = encode(linear[:, row_of] + gains * light[phase_of, row_of].reshape(1, -1, 1))
            lit = ((predicted - pair.attacked[:, row_of]) ** 2).sum(dim=(0, 2)) - unlit[row_of]
            cost = unlit.sum() + torch.zeros(len(phases), dtype=lit.dtype).index_add_(0, phase_of, lit)
        return phases, cost.numpy()

    def best_phase(self, params, index: int) -> float:
        """The pulse phase (rows) that best explains pair ``index`` (registration)."""
        phases, cost = self.phase_costs(params, index)
        return float(phases[int(np.argmin(cost))])

    def latent_candidates(self, fit: Fit, index: int) -> tuple[np.ndarray, np.ndarray]:
        if "exposure_overlap" not in fit.effects:  # the paper's band sits at a fixed place: nothing unknown
            pair = self.pairs[index]
            sse = float(((self.predict_registered(fit, index) - pair.attacked) ** 2).sum())
            return np.array([sse]), np.ones(1)
        _, cost = self.phase_costs(fit.params, index)
        return cost, np.full(len(cost), 1.0 / len(cost))

    def predict_registered(self, fit: Fit, index: int) -> torch.Tensor:
        with torch.no_grad():
            if "exposure_overlap" not in fit.effects:
                params = {k: torch.as_tensor(v, dtype=torch.float64) for k, v in fit.params.items()}
                return self.predict_band(params, index)
            return self.predict_stripe(fit.params, index, self.best_phase(fit.params, index))

    def initial_stripe(self, items: np.ndarray, tone: dict[str, float]) -> dict[str, float]:
        """Start values read from the data: the brightest row's colour and the lit band's height, in the light
        the tone curve ``tone`` (its start parameters) decodes."""
        decode, _ = self.tone(tone)
        peaks, widths = [], []
        for i in items:
            pair = self.pairs[int(i)]
            added = decode(pair.attacked) - decode(pair.clean)
            rows = added.mean(dim=2) / max(pair.intensity, 1e-3)  # (3, H)
            total = rows.sum(0)
            peaks.append(rows[:, int(torch.argmax(total))].clamp(min=0.0).numpy())
            widths.append(float((total > 0.5 * total.max()).double().mean()))
        width = max(float(np.median(widths)), 2.0 / min(p.height for p in self.pairs))
        peak = np.median(np.stack(peaks), axis=0)
        start = {
            "peak_r": float(peak[0]),
            "peak_g": float(peak[1]),
            "peak_b": float(peak[2]),
            "on_share": 0.6 * width,
            "exposure_share": 0.4 * width,
        }
        return {**start, **tone}

    def period_starts(self, stripe: dict[str, float], items: np.ndarray) -> list[dict[str, float]]:
        """Start values for a fitted pulse period: the best local minima of the registered cost over a scan of
        periods. The cost is many-valleyed in the period (a wrong period still matches one stripe in every frame),
        so a local search from a few fixed periods stops in whichever valley it starts in. ``stripe`` holds the
        single-stripe start; with a period shorter than the frame each stripe is only part of one period, and the
        lit share of the rows no longer tells that part, so a few shares of the period are scanned with it."""
        lit = stripe["on_share"] + stripe["exposure_share"]
        on_part = stripe["on_share"] / max(lit, 1e-12)
        candidates = []
        for period in np.geomspace(PERIOD_SCAN[0], PERIOD_SCAN[1], PERIOD_SCAN_STEPS):
            heights = [lit * min(float(period), 1.0)]
            if period < 1.0:
                heights += [share * float(period) for share in STRIPE_SHARES_OF_PERIOD]
            best = None
            for height in heights:
                params = {
                    **stripe,
                    "on_share": on_part * height,
                    "exposure_share": (1.0 - on_part) * height,
                    "period_share": float(period),
                }
                cost = sum(float(self.phase_costs(params, int(i))[1].min()) for i in items)
                if best is None or cost < best[0]:
                    best = (cost, params)
            candidates.append(best)
        costs = np.array([c for c, _ in candidates])
        # valleys of the scan, best first: a scan point no costlier than its neighbours
        valleys = [
            k
            for k in range(len(costs))
            if costs[k] <= costs[max(k - 1, 0)] and costs[k] <= costs[min(k + 1, len(costs) - 1)]
        ]
        valleys.sort(key=lambda k: costs[k])
        return [candidates[k][1] for k in valleys[:PERIOD_STARTS]]

    def stripe_starts(
        self, effects: frozenset[str], items: np.ndarray, nested: Fit | None
    ) -> list[dict[str, float]]:
        """Start values of a stripe model's fit: read from the data, scanned over the period or over the pulse's
        share of the stripe, and the ``nested`` model's fit (selection's warm start), if it has a stripe."""
        tone = {p.name: p.init for p in self.param_specs(effects) if p.name in TONE_PARAMS}
        data = self.initial_stripe(items, tone)
        if "stripe_period" in effects:
            # the scan only picks starting points: run once per model (on the items of its first fit, which
            # selection draws from the fit split), then reused by the other folds
            if effects not in self._period_starts:
                self._period_starts[effects] = self.period_starts(data, items)
            starts = list(self._period_starts[effects])
        else:
            # the stripe is a trapezoid: a plateau |on - exposure| rows long between ramps min(on, exposure) rows
            # long, so the two durations trade against each other and a local search keeps the split it starts
            # from (docs/bench/camsim_session25.md, cause 3)
            lit = data["on_share"] + data["exposure_share"]
            starts = [
                {**data, "on_share": share * lit, "exposure_share": (1.0 - share) * lit}
                for share in ON_SHARES_OF_STRIPE
            ]
        if nested is not None and "exposure_overlap" in nested.effects:
            params = nested.params
            if TONE_EFFECTS & effects != TONE_EFFECTS & nested.effects:
                # colour gains measured in other units (light decoded by another curve): only the stripe's geometry
                params = {
                    k: v for k, v in params.items() if not k.startswith("peak_") and k not in TONE_PARAMS
                }
            starts.insert(0, {**starts[0], **params})
        return starts

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        if "exposure_overlap" not in effects:
            params = fit_least_squares(
                self.param_specs(effects),
                lambda p: torch.cat(
                    [(self.predict_band(p, int(i)) - self.pairs[int(i)].attacked).ravel() for i in items]
                ),
            )
            return self.with_noise(Fit(effects, params), items)
        specs = self.param_specs(effects)
        if start is not None and start.effects == effects:
            # a refit of the same model (bootstrap draws): from its estimate
            starts, rounds = [start.params], 1
        else:
            starts, rounds = self.stripe_starts(effects, items, start), 2
        best: tuple[float, dict] | None = None
        for params in starts:
            for _ in range(rounds):  # alternate: phases given the stripe, stripe given the phases
                phases = {int(i): self.best_phase(params, int(i)) for i in items}

                def residuals(p, phases=phases):
                    predicted = self.predict_stripes(p, items, phases)
                    return torch.cat(
                        [
                            (frame - self.pairs[int(i)].attacked).ravel()
                            for frame, i in zip(predicted, items, strict=True)
                        ]
                    )

                params = fit_least_squares(specs, residuals, warm=params, jacobian="2-point", max_nfev=25)
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
        return self.with_noise(Fit(effects, best[1]), items)

    def with_noise(self, fit: Fit, items: np.ndarray) -> Fit:
        fit.extra["noise_variance"] = self.noise_variance(fit, items)
        return fit

    def identification_checks(self, effect: str, fit: Fit, items: np.ndarray) -> list[str]:
        """A pulse period names a repetition: the stripe must come back inside the frame. Fitted longer than the
        frame, it shows no frame a second stripe; what it fits then is how often a frame holds no stripe at all (a
        pulse falling between two frames' readouts, seen on the independent simulator's single-stripe case), which
        is not a period."""
        period = fit.params.get("period_share")
        if effect != "stripe_period" or period is None or period < 1.0:
            return []
        return [
            f"the fitted period ({period:.3g} frame heights) is longer than the frame: no frame shows the stripe "
            "repeat (it fits how often a pulse misses the frame's readout)"
        ]

    def transform_kwargs(self, fit: Fit) -> dict:
        """``LaserColorStrip`` options: the colour split of the fitted light; with ``exposure_overlap`` the
        rolling-shutter model on a 720-row frame (frame time 1 s scaled away: only shares of the frame matter),
        composed in the light ``sensor_gamma``'s power law or the fitted shoulder decodes. At the pulse phase
        registered on a pair the attack draws what ``predict_stripe`` predicts, and its uniform phase is the model's
        prior over the phase (``phase_costs``' span)."""
        p = fit.params
        if "exposure_overlap" not in fit.effects:
            total = p["strength_r"] + p["strength_g"] + p["strength_b"]
            fractions = [p[f"strength_{c}"] / max(total, 1e-12) for c in "rgb"]
            return {"color_fractions": fractions, "levels": [0.0, total / 3, 2 * total / 3, total]}
        peaks = [p[f"peak_{c}"] for c in "rgb"]
        top = max(max(peaks), 1e-12)
        # no period measured: the model sees one pulse at a time (SINGLE_PULSE_PERIOD) and weighs alike every phase
        # at which its stripe crosses the frame (phase_costs: a frame and a stripe's length, less a row). The
        # attack's pulses come a frame and a stripe's length apart: no two stripes cross one frame, and a uniform
        # phase puts the stripe anywhere it can be seen (a row's worth of phases in 720 shows none)
        period = p.get("period_share", 1.0 + p["on_share"] + p["exposure_share"])
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
            **({"gamma": p["gamma"]} if "sensor_gamma" in fit.effects else {}),
            **(shoulder_kwargs(p) if "tone_shoulder" in fit.effects else {}),
        }

    def derived(self, fit: Fit) -> dict:
        p = fit.params
        if "exposure_overlap" not in fit.effects:
            return {}
        out = {"stripe_rows_share": p["on_share"] + p["exposure_share"]}
        if "period_share" in p:
            out["stripe_period_share"] = p["period_share"]
        return out
