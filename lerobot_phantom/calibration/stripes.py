"""Stripe tables -> ``laser_color_strip``: how many rows a pulsed laser lights in a rolling-shutter camera.

Base (the paper): a fixed band of rows whatever the laser and exposure settings (fitted height; the paper uses
H/3). Extensions follow the rolling shutter term by term (``physics.rolling_shutter_rows_lit`` documents each):
row readout time, the pulse/exposure overlap, the sensor's extra integration time, the detection threshold that
drops partly lit rows, blooming at stripe edges, and the phase drift of a recording whose laser beats slowly with
the frame rate (``phase_drift``: one drift per recording, the rows of one laser frequency and exposure setting;
``drift_from_entry``: each video of it begins as its stripes come whole into view). "Recording" here is that duty-
cycle sweep: the measured tables ("They See Me Rollin'", ``rsa/profile.py``) hold one video per row, and the model
assumes the videos of one sweep share the beat of the laser and frame clocks.
Every prediction is an expectation over the pulse phase (the phase of one frame cannot be known in advance: uniform,
or a whole-stripe placement and the recording's drift from it), so no held-out row informs its own prediction; a
recording's drift is fitted on its fit rows only, and kept only where they call for it beyond their measurement
error (``StripeProblem.drifts_without_evidence``; the standard error of each mean comes from an
``affected_rows_95ci``/``affected_rows_99ci`` column when the table has one). A ``recording_frames`` column (the
frames of each row's video) sets how many frames a drifting recording's mean is over; without it the recordings are
taken as long.

Units and geometry come from the table when it says them (``exposure_us``/``exposure_ms``/``exposure_s`` columns
or values such as ``32us``; an ``image_height``/``image_rows`` column); otherwise ``--exposure-unit-s`` and
``--image-height`` are required. A ``camera`` column is only checked to hold one camera: names never imply units.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from lerobot_phantom.calibration.core import (
    TIE_SHARE,
    Effect,
    Fit,
    Param,
    Problem,
    binned_rmse,
    fit_least_squares,
    kfold,
    preferred_fit,
    ties_lowest,
)
from lerobot_phantom.calibration.structure import ResidualSample
from lerobot_phantom.transforms.physics import STRIPE_FRAME_RULES, rolling_shutter_rows_lit

STRIPE_COLUMNS = ("frequency", "exposure", "duty_cycle", "affected_rows_mean")
EXPOSURE_COLUMN_UNITS = {"exposure_s": 1.0, "exposure_ms": 1e-3, "exposure_us": 1e-6}
HEIGHT_COLUMNS = ("image_height", "image_rows")
SPREAD_COLUMN = "affected_rows_std"
# how many frames the video behind each row holds: a drifting recording's mean over its lit frames depends on it
# (physics.rolling_shutter_rows_lit, recording length); without it the kernel takes a long recording's limit
RECORDING_FRAMES_COLUMN = "recording_frames"
# a row's confidence half-width of its mean over frames, and the normal quantile it was taken at ("They See Me
# Rollin'" tables give both): the standard error of each measured mean
CONFIDENCE_COLUMNS = {"affected_rows_95ci": 1.959964, "affected_rows_99ci": 2.575829}
# unit suffixes a value may carry (case-insensitive); "u" and the micro sign both mean microseconds
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "μs": 1e-6, "ns": 1e-9}
FREQUENCY_UNITS = {"hz": 1.0, "khz": 1e3, "mhz": 1e6}
FRAME_RULE_CHOICES = ("auto", *STRIPE_FRAME_RULES)
# stripe fits take exact derivatives (torch reverse mode; core.JACOBIANS says why not forward mode): on
# test_the_first_fit_finds_the_stripe_count_regime_of_the_camera[24-interior] finite differences (2- and 3-point
# alike) stop in another offset/threshold minimum, 7.42 rows against the 1.50 exact derivatives reach
STRIPE_JACOBIAN = "reverse"

# The kernel's blooming term (spread_rows) is not a candidate, and the model never sets it: for one stripe per frame
# at least a row wide it adds the same rows as integration_offset, so the two cannot be told apart from stripe
# tables; they differ only for stripes narrower than a row time, which bloom in the share of frames that light a row.
EFFECTS = (
    Effect(
        "exposure_overlap",
        "a rolling shutter exposes rows one after another (one row time apart); a row is lit when its exposure "
        "window overlaps a laser pulse, so each stripe spans (pulse on-time + exposure) / row time rows, stripes "
        "repeat every laser period, and the mean over a random pulse phase replaces a fixed band",
    ),
    Effect(
        "integration_offset",
        "the sensor integrates light a constant time longer (or shorter) than the nominal exposure setting, "
        "widening every stripe by the same number of rows",
        requires=("exposure_overlap",),
    ),
    Effect(
        "detection_threshold",
        "a row counts as lit only when it collects a minimum on-time of laser light: rows at a stripe's edges, "
        "lit for part of their exposure, drop out, and nothing is seen once pulse and exposure are both shorter",
        requires=("exposure_overlap",),
    ),
    Effect(
        "detection_noise",
        "read noise makes the threshold soft: rows whose collected light is near it are lit in some frames and "
        "not in others, so conditions at the edge of visibility still light a share of rows",
        requires=("detection_threshold",),
    ),
    Effect(
        "phase_drift",
        "a laser whose frequency is close to a multiple of the frame rate beats with it slowly: within one "
        "recording the stripes start where they were placed whole in view and drift over part of a laser period, "
        "so wide stripes are cut by the frame's edges in part of the frames; how far the phase drifted belongs to "
        "each recording (the rows of one laser frequency and exposure setting)",
        requires=("exposure_overlap",),
    ),
    Effect(
        "drift_from_entry",
        "a drifting recording begins at the first frame that shows its stripes whole, as they come into view (a "
        "recording started once the stripe is in view), not at any whole placement: its stripes cross the frame's "
        "whole free span before an edge cuts them, so a small drift cuts only stripes that nearly fill the frame",
        requires=("phase_drift",),
    ),
)
DRIFT_EFFECTS = ("phase_drift", "drift_from_entry")
# a recording's drift, as a share of the laser period, is searched on this grid before the joint fit: at 0 the
# error is flat in it (a small drift cuts no stripe), so a fit started there never leaves
DRIFT_GRID = np.concatenate([[0.0], np.geomspace(0.01, 1.0, 24)])
# a recording's drift is one parameter per recording: with fewer rows per recording on average it is a fudge per
# row, not a measurement, and phase_drift is not offered (the report says so)
MIN_ROWS_PER_RECORDING = 4
# the drift's grid makes its error piecewise: finite differences reach the fit exact derivatives reach, at a third of
# forward mode's CPU and a fifteenth of reverse mode's (session 28, the Axis table)
DRIFT_JACOBIAN = "2-point"
# a recording keeps its drift when its fit rows' variance-weighted squared error drops by at least this much against a
# lock: the 5% critical value of the likelihood ratio for one parameter at its bound (a 50:50 mixture of 0 and
# chi-square with one degree of freedom; Self & Liang 1987)
DRIFT_EVIDENCE = 2.706
# a threshold's flat (StripeProblem.threshold_at_flat_floor) is traced on this log grid over its range, from this
# share of the range's top: its steps are found to 1.6% of the threshold, and a flat reaching below is not bracketed
THRESHOLD_FLAT_GRID = 600
THRESHOLD_FLAT_RANGE = 1e-4
# folds of the fit rows that validate a move along the threshold's flat line (line_move_validates), and their seed
LINE_MOVE_FOLDS = 4
LINE_MOVE_SEED = 0


def _value_and_unit(value, what: str) -> tuple[float, str]:
    if isinstance(value, int | float | np.number):
        return float(value), ""
    match = re.search(r"([-+]?\d*\.?\d+(?:[eE][-+]?\d+)?)\s*([A-Za-zµμ]*)\s*$", str(value).strip())
    if match is None:
        raise ValueError(f"cannot read a number from {what} value {value!r}")
    return float(match.group(1)), match.group(2)


def _frequencies_hz(values) -> np.ndarray:
    out = []
    for value in values:
        number, unit = _value_and_unit(value, "frequency")
        if unit and unit.lower() not in FREQUENCY_UNITS:
            raise ValueError(
                f"frequency {value!r}: unknown unit {unit!r}; valid: Hz, kHz, MHz or a plain number (Hz)"
            )
        out.append(number * FREQUENCY_UNITS.get(unit.lower(), 1.0))
    return np.array(out)


def _exposures(values) -> tuple[np.ndarray, float | None]:
    """Exposure numbers and, if every value names a time unit, that unit in seconds (else None)."""
    numbers, units = [], set()
    for value in values:
        number, unit = _value_and_unit(value, "exposure")
        numbers.append(number)
        units.add(unit)
    known = {u for u in units if u.lower() in TIME_UNITS or u in TIME_UNITS}
    if len(units) == 1 and known:
        (unit,) = known
        return np.array(numbers), TIME_UNITS.get(unit, TIME_UNITS.get(unit.lower()))
    if known and len(units) > 1:
        raise ValueError(f"exposure values mix units {sorted(units)}; give every value in one unit")
    return np.array(numbers), None


def is_stripe_table(columns) -> bool:
    columns = set(columns)
    has_exposure = "exposure" in columns or bool(columns & set(EXPOSURE_COLUMN_UNITS))
    return has_exposure and {"frequency", "duty_cycle", "affected_rows_mean"} <= columns


def read_stripe_table(
    path: Path, *, image_height: int | None, exposure_unit_s: float | None
) -> tuple[pd.DataFrame, dict]:
    """The table plus its units and geometry, read from the data where it states them, else from the flags.

    Returns ``(table, meta)`` with ``meta`` holding ``frequency_hz``, ``duty``, ``exposure_s`` (arrays),
    ``image_height`` and ``sources`` (where each unit came from, for the report).
    """
    table = pd.read_csv(path)
    if not is_stripe_table(table.columns):
        raise ValueError(
            f"{path}: stripe table needs columns frequency, exposure (or exposure_s / exposure_ms / exposure_us), "
            f"duty_cycle, affected_rows_mean; has {list(table.columns)}"
        )
    if "camera" in table.columns and table["camera"].nunique() > 1:
        raise ValueError(
            f"{path}: the table mixes cameras {sorted(map(str, table['camera'].unique()))}; camera parameters "
            "(row time, threshold) differ per camera, so calibrate one camera per table"
        )
    sources: dict[str, str] = {}
    exposure, data_unit = _exposure_values_and_unit(path, table, exposure_unit_s, sources)
    image_height = _image_height(path, table, image_height, sources)
    frequency_hz = _frequencies_hz(table["frequency"])
    duty = np.array([_value_and_unit(v, "duty_cycle")[0] for v in table["duty_cycle"]]) / 100.0
    sources["frequency"] = "Hz (unit written in the values, or plain numbers read as Hz)"
    sources["duty_cycle"] = "percent of the laser period"
    rows = table["affected_rows_mean"].to_numpy(dtype=np.float64)
    if (frequency_hz <= 0).any() or not np.isfinite(rows).all() or ((duty <= 0) | (duty > 1)).any():
        raise ValueError(
            f"{path}: frequencies must be positive, duty cycles in (0, 100] and row counts finite"
        )
    # the frames' spread of each row's count, when the table gives it: a diagnosis of rows whose frames disagree
    spread = table[SPREAD_COLUMN].to_numpy(dtype=np.float64) if SPREAD_COLUMN in table.columns else None
    standard_error = np.zeros(len(rows))
    for column, quantile in CONFIDENCE_COLUMNS.items():
        if column in table.columns:
            standard_error = table[column].to_numpy(dtype=np.float64) / quantile
            sources["standard_error"] = f"column {column} / {quantile:.4g}"
            break
    else:
        sources["standard_error"] = "none in the table: model error only"
    if not np.isfinite(standard_error).all() or (standard_error < 0).any():
        raise ValueError(f"{path}: confidence half-widths must be finite and non-negative")
    recording_frames = None
    if RECORDING_FRAMES_COLUMN in table.columns:
        recording_frames = pd.to_numeric(table[RECORDING_FRAMES_COLUMN], errors="coerce").to_numpy(np.float64)
        if (
            not (np.isfinite(recording_frames) & (recording_frames >= 1)).all()
            or (recording_frames != np.round(recording_frames)).any()
        ):
            raise ValueError(
                f"{path}: column {RECORDING_FRAMES_COLUMN} must hold whole frame counts >= 1 (the frames of the "
                "video behind each row)"
            )
        sources["recording_frames"] = f"column {RECORDING_FRAMES_COLUMN}"
    else:
        sources["recording_frames"] = (
            f"no {RECORDING_FRAMES_COLUMN} column: a drifting recording is taken as long (the arc's limit)"
        )
    meta = {
        "spread": spread,
        "standard_error": standard_error,
        "recording_frames": recording_frames,
        "frequency_hz": frequency_hz,
        "duty": duty,
        "exposure_s": exposure * data_unit,
        "exposure_setting": exposure,
        "rows": rows,
        "image_height": int(image_height),
        "sources": sources,
    }
    return table, meta


def _exposure_values_and_unit(
    path: Path, table: pd.DataFrame, exposure_unit_s: float | None, sources: dict[str, str]
) -> tuple[np.ndarray, float]:
    """The exposure settings and seconds per unit: from the column's name, the values' written units, or
    ``--exposure-unit-s``, whichever states it (two that disagree are an error); records the source."""
    named = [c for c in EXPOSURE_COLUMN_UNITS if c in table.columns]
    found = [*named, *(["exposure"] if "exposure" in table.columns else [])]
    if len(found) > 1:
        raise ValueError(f"{path}: several exposure columns {found}; keep one")
    if named:
        exposure, data_unit = _exposures(table[named[0]])
        column_unit = EXPOSURE_COLUMN_UNITS[named[0]]
        if data_unit is not None and data_unit != column_unit:
            raise ValueError(f"{path}: column {named[0]} holds values in another unit")
        data_unit, sources["exposure"] = column_unit, f"column {named[0]}"
    else:
        exposure, data_unit = _exposures(table["exposure"])
        sources["exposure"] = "units written in the exposure values"
    if data_unit is None:
        if exposure_unit_s is None:
            example = table[named[0] if named else "exposure"].iloc[0]
            raise ValueError(
                f"{path}: exposure values such as {example!r} carry no unit; give --exposure-unit-s (seconds per "
                "unit: 1e-4 for UVC cameras such as the Logitech table, 1e-6 for microseconds, 1e-3 for "
                "milliseconds) or name the column exposure_s / exposure_ms / exposure_us"
            )
        if exposure_unit_s <= 0:
            raise ValueError(f"--exposure-unit-s must be positive, got {exposure_unit_s}")
        data_unit, sources["exposure"] = float(exposure_unit_s), "--exposure-unit-s"
    elif exposure_unit_s is not None and not np.isclose(exposure_unit_s, data_unit):
        raise ValueError(
            f"{path}: --exposure-unit-s {exposure_unit_s} contradicts the table ({sources['exposure']}: "
            f"{data_unit} s per unit); drop the flag"
        )
    return exposure, data_unit


def _image_height(path: Path, table: pd.DataFrame, image_height: int | None, sources: dict[str, str]) -> int:
    """The frame height in rows: from an image_height column or ``--image-height`` (one that contradicts the
    other is an error); records the source."""
    heights = [c for c in HEIGHT_COLUMNS if c in table.columns]
    if heights:
        values = table[heights[0]].unique()
        if len(values) != 1:
            raise ValueError(
                f"{path}: column {heights[0]} holds several heights {sorted(values)}; one per table"
            )
        data_height = int(values[0])
        if image_height is not None and image_height != data_height:
            raise ValueError(
                f"{path}: --image-height {image_height} contradicts column {heights[0]} ({data_height}); drop the flag"
            )
        image_height, sources["image_height"] = data_height, f"column {heights[0]}"
    elif image_height is None:
        raise ValueError(
            f"{path}: the table does not give the frame height; give --image-height (rows of the camera's frames, "
            "e.g. 720 for the Logitech table) or add an image_height column"
        )
    else:
        sources["image_height"] = "--image-height"
    if image_height <= 0:
        raise ValueError(f"--image-height must be positive, got {image_height}")
    return int(image_height)


class StripeProblem(Problem):
    attack = "laser_color_strip"
    input_kind = "stripe_table"
    units = "rows"
    item_name = "table rows"
    base_model = "fixed band of rows (the paper's laser color strip, band height fitted)"
    extended_model = "rolling shutter: phase-averaged pulse/exposure overlap over the row readout"
    candidates = EFFECTS
    # threshold, read noise and offset can pay only together (drawn camera 4111198912, lit: docs/bench/session56.md)
    joint_effects = 3
    # A table is a sparse grid of conditions over a response that switches regime (pulses above or below the
    # detection threshold, one or several pulses per exposure). A condition alone in its regime cannot be predicted
    # by the fold that validates it, whatever the model: its error (hundreds of rows) would decide every squared-
    # error comparison, while the rows each model can predict would not count.
    selection_score = "mean_item_error"
    selection_score_reason = (
        "each table row's absolute error, averaged: a condition alone in its regime, which no fold that validates "
        "it can predict, must not decide every comparison"
    )
    # A threshold and a negative integration offset shorten every stripe alike (on + window + offset - 2 threshold)
    # and part only where a pulse or window is shorter than the threshold; fit rows with no such condition score
    # the two equal. Every table is measured by a detection rule (a row counts when a pixel clears a level above the
    # dark frame), so the threshold is there in any case; a negative offset is a claim about the sensor's timing
    # that such rows cannot back.
    tie_preference = ("detection_threshold",)
    tie_preference_reason = (
        "every table is counted by a detection rule, and fit rows that no pulse or window shorter than the "
        "threshold reaches cannot tell it from a negative integration offset"
    )

    def __init__(
        self,
        path: Path,
        *,
        image_height: int | None,
        exposure_unit_s: float | None,
        frames: str = "auto",
    ) -> None:
        if frames not in FRAME_RULE_CHOICES:
            raise ValueError(f"--stripe-frames {frames!r} unknown; valid: {', '.join(FRAME_RULE_CHOICES)}")
        _table, meta = read_stripe_table(path, image_height=image_height, exposure_unit_s=exposure_unit_s)
        self.path = path
        self.frame_rules = STRIPE_FRAME_RULES if frames == "auto" else (frames,)
        self.image_height = meta["image_height"]
        self.sources = meta["sources"]
        self.frequency_hz = meta["frequency_hz"]
        self.duty = meta["duty"]
        self.exposure_s = meta["exposure_s"]
        self.exposure_setting = meta["exposure_setting"]
        self.rows = meta["rows"]
        self.spread = meta["spread"]
        self.standard_error = meta["standard_error"]
        self.recording_frames = meta["recording_frames"]
        # a recording: the rows of one laser frequency and exposure setting (a duty-cycle sweep, one video per row
        # in the measured tables), assumed to share the beat of the laser and frame clocks
        keys = np.c_[self.frequency_hz, self.exposure_s]
        _, first, self.recording = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        self.recording = self.recording.ravel()
        self.drift_names = [
            f"drift_{self.frequency_hz[i]:g}Hz_exposure{self.exposure_setting[i]:g}" for i in first
        ]
        self.rows_per_recording = self.n_items / len(self.drift_names)
        self.drift_offered, self.drift_offer_reason = self.drift_offer()
        if not self.drift_offered:
            self.candidates = tuple(e for e in EFFECTS if e.name not in DRIFT_EFFECTS)

    @property
    def n_items(self) -> int:
        return len(self.rows)

    def recording_facts(self) -> dict[str, str]:
        return {"image_height": str(self.image_height), **{f"{k}_source": v for k, v in self.sources.items()}}

    # -- model ---------------------------------------------------------------------------------------------
    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        height = self.image_height
        if "exposure_overlap" not in effects:
            return [Param("band_rows", height / 3.0, 0.0, float(height), scale=height / 3.0)]
        # start: a full-frame readout in 1/30 s (other readouts are tried as further starts, see fit); bounds: a
        # video camera reads a frame out in 0.1 ms .. 200 ms
        row_time = 1.0 / (30.0 * height)
        specs = [Param("row_time_s", row_time, 1e-4 / height, 0.2 / height, scale=row_time)]
        exposure = float(np.median(self.exposure_s))
        shortest = float(np.min(np.minimum(self.exposure_s, self.duty / self.frequency_hz)))
        if "integration_offset" in effects:
            # the sensor may add up to the longest exposure setting, and cannot remove more than the shortest
            specs.append(
                Param(
                    "integration_offset_s",
                    0.0,
                    -float(self.exposure_s.min()),
                    float(self.exposure_s.max()),
                    scale=exposure,
                )
            )
        if "detection_threshold" in effects:
            specs.append(
                Param("threshold_s", 0.1 * shortest, 0.0, exposure + shortest, scale=max(shortest, 1e-7))
            )
        if "detection_noise" in effects:
            specs.append(
                Param("noise_s", 0.3 * shortest, 0.0, exposure + shortest, scale=max(shortest, 1e-7))
            )
        if "phase_drift" in effects:
            specs += [
                Param(
                    name,
                    0.0,
                    0.0,
                    1.0,
                    scale=0.1,
                    low_limit="a phase locked to the frame rate: every frame sees the stripes where they were placed",
                    high_limit="a phase that covers the whole laser period: any phase, as under the 'lit' rule",
                )
                for name in self.drift_names
            ]
        return specs

    def predict(
        self, effects: frozenset[str], params: dict, items: np.ndarray, frames: str = "lit"
    ) -> torch.Tensor:
        if "exposure_overlap" not in effects:
            return torch.as_tensor(params["band_rows"], dtype=torch.float64).expand(len(items))
        drift, recording_frames = None, None
        if "phase_drift" in effects:
            # a drift starts from the interior rule's placements: fit_drift fits it under that rule only
            drift = torch.stack(
                [torch.as_tensor(params[n], dtype=torch.float64) for n in self.drift_names], -1
            )
            drift = drift[..., torch.as_tensor(self.recording[items])]
            if self.recording_frames is not None:
                recording_frames = torch.as_tensor(self.recording_frames[items])
        return rolling_shutter_rows_lit(
            torch.as_tensor(self.frequency_hz[items]),
            torch.as_tensor(self.duty[items]),
            torch.as_tensor(self.exposure_s[items]),
            params["row_time_s"],
            image_rows=self.image_height,
            integration_offset_s=params.get("integration_offset_s", 0.0),
            threshold_s=params.get("threshold_s", 0.0),
            noise_s=params.get("noise_s"),
            frames=frames,
            drift=drift,
            drift_start="entry" if "drift_from_entry" in effects else "placement",
            recording_frames=recording_frames,
        )

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        """Least squares per frame rule (which frames the table averaged; see ``rolling_shutter_rows_lit``),
        keeping the rule with the lower fit error; row time is started from several frame readouts.

        A refit of the same model on resampled rows (a bootstrap draw: ``start`` is the estimate) keeps the
        estimate's frame rule, a discrete choice of model like its effects, which intervals are conditional on. It
        repeats a first fit's search (its starts and five stripe-count regimes), and starts from the estimate too:
        one started only from the estimate stays in its regime, and the interval then measures that regime's width,
        not the row time's uncertainty (the Logitech table's single laser frequency fits a 35 ms and a 138 ms
        readout alike; refits from the estimate alone gave a row time of 47.8-48.9 us, refits that search
        48.0-191 us). A model with ``phase_drift`` is fitted by ``fit_drift``."""
        if "phase_drift" in effects:
            return self.fit_drift(effects, items, start)
        return self.fit_rules(effects, items, start, self.frame_rules)

    def fit_rules(
        self, effects: frozenset[str], items: np.ndarray, start: Fit | None, rules: tuple[str, ...]
    ) -> Fit:
        """``fit`` under the frame ``rules`` given (a refit keeps its estimate's)."""
        target = torch.as_tensor(self.rows[items])
        specs = self.param_specs(effects)
        if "exposure_overlap" not in effects:
            params = fit_least_squares(
                specs, lambda p: self.predict(effects, p, items) - target, jacobian=STRIPE_JACOBIAN
            )
            return Fit(effects, params)
        # the error surface has a local minimum per stripe-count regime (row time) and per threshold regime:
        # each rule's fit starts from the best points of a grid (evaluated in one batched call) and from the
        # given model's values (a nested model's, or this model's estimate)
        first = {p.name: p.init for p in specs}
        if start is not None:
            first.update({k: v for k, v in start.params.items() if k in first})
        grid = self.start_grid(specs, first)
        per_rule = []
        # every rule starts from the given values and the grid's best points of distinct row times (five for a
        # first fit and a bootstrap refit: neighbouring stripe-count regimes, e.g. a row time and its double, are
        # separate minima, and the grid's ranking of them is coarse), two points of each (offset/threshold minima
        # within a regime)
        refit = start is not None and start.effects == effects and "frames" in start.extra
        n_grid = 2 if start is not None and "frames" in start.extra and not refit else 5
        for rule in (start.extra["frames"],) if refit else rules:
            with torch.no_grad():
                batched = {k: torch.as_tensor(v).reshape(-1, 1) for k, v in grid.items()}
                sse = ((self.predict(effects, batched, items, rule) - target) ** 2).sum(-1)
            order = torch.argsort(torch.nan_to_num(sse, nan=float("inf"))).tolist()
            # a refit also starts where a first fit does: its starts hold every start of a first fit under its rule
            tries = (
                [first]
                + ([{p.name: p.init for p in specs}] if refit else [])
                + [{k: float(v[i]) for k, v in grid.items()} for i in self.regime_starts(grid, order, n_grid)]
            )
            fits = [self.fit_from(effects, specs, items, rule, initial) for initial in tries]
            error, params = preferred_fit(specs, fits)
            beside = [
                self.fit_from(effects, specs, items, rule, s)
                for s in self.threshold_regimes_beside(effects, params, items)
            ]
            error, params = preferred_fit(specs, [(error, params), *beside])
            per_rule.append((*self.threshold_at_flat_floor(effects, specs, items, rule, error, params), rule))
        _, params, rule = preferred_fit(specs, per_rule)
        return Fit(effects, params, {"frames": rule})

    def fit_from(
        self,
        effects: frozenset[str],
        specs: list[Param],
        items: np.ndarray,
        rule: str,
        initial: dict[str, float],
    ) -> tuple[float, dict[str, float]]:
        """(squared error, parameters) of one least-squares fit under frame ``rule`` started at ``initial``."""
        target = torch.as_tensor(self.rows[items])
        params = fit_least_squares(
            specs,
            lambda p: self.predict(effects, p, items, rule) - target,
            warm=initial,
            jacobian=STRIPE_JACOBIAN,
        )
        with torch.no_grad():
            values = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
            return float(torch.sum((self.predict(effects, values, items, rule) - target) ** 2)), params

    def threshold_regimes_beside(
        self, effects: frozenset[str], params: dict[str, float], items: np.ndarray
    ) -> list[dict[str, float]]:
        """Starts in the two threshold regimes beside the one of ``params``. Without read noise the error is flat in
        the threshold between the light the rows' pulses can give at most (``min(on-time, exposure + offset)``; a
        threshold between two of them sees the same pulses) and steps where it crosses one, with no slope to lead a
        fit across: a fit ends in the regime its row-time search left it in. Each start lies just beyond the
        nearest step below and above the threshold (not past the next one). Seen on the drawn tables of
        tests/calibration/test_stripes.py: a threshold that had crossed a 1% pulse (21.4 us) while the row time was
        still far off ended at 7.4 rows where 1.3 lay just under that step; one that stopped under a 16.2 us pulse
        ended at 3.3 rows where the camera's own threshold (18.8 us, the pulse seen through read noise) gives 0.8."""
        if "detection_threshold" not in effects or "detection_noise" in effects:
            return []
        window = self.exposure_s[items] + params.get("integration_offset_s", 0.0)
        steps = np.unique(np.minimum(self.duty[items] / self.frequency_hz[items], window))
        threshold = params["threshold_s"]
        below, above = steps[steps <= threshold], steps[steps > threshold]
        starts = []
        if len(below):
            nearest, next_one = below[-1], below[-2] if len(below) > 1 else 0.0
            starts.append(max(0.95 * nearest, 0.5 * (nearest + next_one)))
        if len(above):
            nearest, next_one = above[0], above[1] if len(above) > 1 else np.inf
            starts.append(min(1.05 * nearest, 0.5 * (nearest + next_one)))
        return [{**params, "threshold_s": float(start)} for start in starts]

    def threshold_at_flat_floor(
        self,
        effects: frozenset[str],
        specs: list[Param],
        items: np.ndarray,
        rule: str,
        error: float,
        params: dict[str, float],
    ) -> tuple[float, dict[str, float]]:
        """(squared error, parameters) with the threshold moved to the floor of its flat, when the fit rows bracket
        it; else the fit as it is. Without read noise a threshold between two steps (the most light a row shown dark
        collects and the least a row shown lit collects) gives every fit row the same count, and a threshold moved
        by ``d`` with the offset moved by ``2 d`` keeps every stripe's width (``on + window + offset - 2
        threshold``): the error is exactly flat along that line, and where a fit stops on it is where its start
        left it, so folds of one table stop at different thresholds for no reason in their rows. The floor is the
        least light lost that the fit rows call for (the threshold nearest its null, as selection prefers no effect
        the data do not call for); it is found on a log grid, so to within its step (1.6%) above the step
        below. Seen on drawn camera 531200696 (lit frames, ``docs/bench/session52.md``): a selection fold whose fit
        rows show an 18.8 us pulse dark and a 48.1 us pulse lit stopped at 46.5 us and darkened the 36.6 us pulses
        it validates (61.8 rows against 3.5 for any threshold under 36.6; the camera's is 26.8), and selection wrote
        the overlap alone (215 rows held-out against 9.4). A flat reaching either end of the threshold's range is
        not bracketed, and the fit stays; so does a fit with read noise, whose error has a slope everywhere.

        Before the floor, the fit may move to the lowest error the line reaches: a fit cannot cross a step with no
        slope before it, and the starts ``threshold_regimes_beside`` gives lie beside the steps of windows holding
        one pulse, where a window holding ``k`` pulses collects ``k`` on-times, a step too. It moves only where the
        move validates (``line_move_validates``): a lower error on another flat can come from the rows of one fold
        alone (on the multi-pulse table below, a single row), and a move they alone ask for is no evidence that the
        rows to be predicted lie on that flat. Seen both ways: on the multi-pulse table
        (``docs/bench/session52/multi_pulse_steps_probe.py``) a fit stopped at 37.7 us on a 37.5-48.1 us flat,
        squared error 86722, where the line reaches 520 on the 28.8-37.5 us flat beside it; on drawn camera
        4111198912 (lit frames, sampled pulses) two selection folds' fits moved (6433 -> 2406), validated worse, and
        selection wrote the overlap alone, 2.80 -> 340.66 rows held-out (``docs/bench/session53.md``); in both, the
        line's gain lies in one fold's rows. Neither move validates; one witnessed by rows of several folds does
        (``docs/bench/session54.md``)."""
        if "detection_threshold" not in effects or "detection_noise" in effects:
            return error, params
        grid, moved, errors, inside = self.threshold_line(effects, specs, items, rule, params)
        sse = errors.sum(1)
        lowest = int(np.argmin(np.where(inside, sse, np.inf)))
        at = int(np.searchsorted(grid, params["threshold_s"]))  # the fit's own point: the grid holds it
        if (
            inside[lowest]
            and sse[lowest] < error - abs(error) * TIE_SHARE
            and line_move_validates(errors, inside, at)
        ):
            reached = {**params, **{k: float(v[lowest]) for k, v in moved.items()}}
            refit = self.fit_from(effects, specs, items, rule, reached)
            error, params = preferred_fit(specs, [(float(sse[lowest]), reached), refit])
            grid, moved, errors, inside = self.threshold_line(effects, specs, items, rule, params)
            sse = errors.sum(1)
            at = int(np.searchsorted(grid, params["threshold_s"]))
        flat = inside & (np.abs(sse - error) <= abs(error) * TIE_SHARE)
        if not flat[at]:
            return error, params
        low, high = at, at
        while low > 0 and flat[low - 1]:
            low -= 1
        while high < len(grid) - 1 and flat[high + 1]:
            high += 1
        if low == 0 or high == len(grid) - 1:
            return error, params
        # the floor's point of the traced line: its error ties the fit's (it is on the flat)
        return float(sse[low]), {**params, **{k: float(v[low]) for k, v in moved.items()}}

    def threshold_line(
        self,
        effects: frozenset[str],
        specs: list[Param],
        items: np.ndarray,
        rule: str,
        params: dict[str, float],
    ) -> tuple[np.ndarray, dict[str, np.ndarray], np.ndarray, np.ndarray]:
        """The line ``threshold + d, offset + 2 d`` through ``params`` (along which every stripe keeps its width),
        traced on ``THRESHOLD_FLAT_GRID`` log-spaced thresholds over the threshold's range and ``params``' own:
        (thresholds, the moved parameters at each, the fit rows' squared error at each, whether the offset stays
        inside its range)."""
        spec = next(p for p in specs if p.name == "threshold_s")
        current = params["threshold_s"]
        grid = np.unique(
            np.r_[np.geomspace(spec.high * THRESHOLD_FLAT_RANGE, spec.high, THRESHOLD_FLAT_GRID), current]
        )
        moved = {"threshold_s": grid}
        inside = np.ones(len(grid), bool)
        offset_spec = {p.name: p for p in specs}.get("integration_offset_s")
        if "integration_offset_s" in params:
            moved["integration_offset_s"] = params["integration_offset_s"] + 2.0 * (grid - current)
            if offset_spec is not None:
                offset = moved["integration_offset_s"]
                inside = (offset >= offset_spec.low) & (offset <= offset_spec.high)
        target = torch.as_tensor(self.rows[items])
        values = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
        values |= {k: torch.as_tensor(v).reshape(-1, 1) for k, v in moved.items()}
        with torch.no_grad():
            errors = ((self.predict(effects, values, items, rule) - target) ** 2).numpy()
        return grid, moved, errors, inside

    def fit_drift(self, effects: frozenset[str], items: np.ndarray, start: Fit | None) -> Fit:
        """The model with ``phase_drift``: the locked model (every drift 0) fitted under the interior rule, whose
        placements the drift starts from, by ``fit``'s search (or ``start`` itself when it is that model, fitted on
        these items by the selection step it extends); then each recording's drift from ``DRIFT_GRID``
        (recordings share no drift, so one batched evaluation scores every recording at every grid value); then
        all parameters jointly from there; then the drifts their recordings' fit rows do not call for
        (``drifts_without_evidence``) are locked and the rest refitted once (listed in the fit's extra)."""
        locked = effects - set(DRIFT_EFFECTS)
        if start is not None and start.effects == locked and start.extra.get("frames") == "interior":
            base = start  # the locked model on these very items (the selection step's fit it extends)
        else:
            shared = None
            if start is not None:
                kept = {k: v for k, v in start.params.items() if k not in self.drift_names}
                shared = Fit(locked, kept, {"frames": "interior"})
            base = self.fit_rules(locked, items, shared, ("interior",))
        target = torch.as_tensor(self.rows[items])
        grid = torch.as_tensor(DRIFT_GRID)
        values = {k: torch.tensor(v, dtype=torch.float64) for k, v in base.params.items()}
        with torch.no_grad():
            predicted = self.predict(effects, values | {n: grid for n in self.drift_names}, items, "interior")
        squared = ((predicted - target) ** 2).numpy()
        recordings = self.recording[items]
        warm = dict(base.params)
        for index, name in enumerate(self.drift_names):
            mine = recordings == index
            warm[name] = float(DRIFT_GRID[np.argmin(squared[:, mine].sum(1))]) if mine.any() else 0.0
        specs = self.param_specs(effects)
        params = fit_least_squares(
            specs,
            lambda p: self.predict(effects, p, items, "interior") - target,
            warm=warm,
            jacobian=DRIFT_JACOBIAN,
        )
        unsupported = self.drifts_without_evidence(effects, params, items)
        if unsupported:
            # the drifts the recordings' own fit rows do not call for are locked, the rest refitted with them
            pinned = dict.fromkeys(unsupported, 0.0)
            free = [spec for spec in specs if spec.name not in pinned]
            refitted = pinned | fit_least_squares(
                free,
                lambda p: self.predict(effects, p | pinned, items, "interior") - target,
                warm={k: v for k, v in params.items() if k not in pinned},
                jacobian=DRIFT_JACOBIAN,
            )
            params = {spec.name: refitted[spec.name] for spec in specs}
        return Fit(effects, params, {"frames": "interior", "drifts_locked_for_want_of_evidence": unsupported})

    def drifts_without_evidence(self, effects: frozenset[str], params: dict, items: np.ndarray) -> list[str]:
        """The recordings' drifts that their own fit rows do not call for: a drift is a parameter per recording,
        and a recording whose one cut video sits within its measurement error, or whose fit stripes are all narrow
        enough that the drift cuts none, must not carry it to its other videos (in a selection fold of the Axis
        table a drift that moved one fit video of a sweep, lowering the weighted error below by 1.95, cut the
        sweep's locked 30% video by over 100 rows). Per recording, the likelihood ratio of its fitted drift against
        a lock: the drop in its fit rows' squared error, each row weighted by its variance (the row's standard
        error of the mean from the table, plus the model's error beyond measurement, estimated from every fit row's
        residual). A drift is kept when the drop reaches ``DRIFT_EVIDENCE`` (the 5% critical value of a likelihood
        ratio for a parameter at its bound)."""
        drifting = [n for n in self.drift_names if params[n] > 0.0]
        if not drifting:
            return []
        values = {k: torch.tensor(v, dtype=torch.float64) for k, v in params.items()}
        with torch.no_grad():
            fitted = self.predict(effects, values, items, "interior").numpy()
            locked = self.predict(
                effects,
                values | {n: torch.tensor(0.0, dtype=torch.float64) for n in drifting},
                items,
                "interior",
            ).numpy()
        measured_variance = self.standard_error[items] ** 2
        model_variance = max(float(np.mean((fitted - self.rows[items]) ** 2 - measured_variance)), 1e-9)
        drop = ((locked - self.rows[items]) ** 2 - (fitted - self.rows[items]) ** 2) / (
            model_variance + measured_variance
        )
        recordings = self.recording[items]
        return [
            name
            for name in drifting
            if drop[recordings == self.drift_names.index(name)].sum() < DRIFT_EVIDENCE
        ]

    @staticmethod
    def regime_starts(
        grid: dict[str, np.ndarray], order: list[int], n: int, per_row_time: int = 2
    ) -> list[int]:
        """The best grid points (``order``: best first) of the ``n`` best distinct row times, ``per_row_time`` of
        each: within one stripe-count regime the offset and threshold still have separate minima (a grid's best
        point can lead to 4x the error its second-best reaches)."""
        chosen: dict[float, list[int]] = {}
        for i in order:
            row_time = float(grid["row_time_s"][i])
            if row_time not in chosen and len(chosen) < n:
                chosen[row_time] = []
            if row_time in chosen and len(chosen[row_time]) < per_row_time:
                chosen[row_time].append(i)
        return [i for points in chosen.values() for i in points]

    def start_grid(self, specs: list[Param], first: dict[str, float]) -> dict[str, np.ndarray]:
        """Starting points: frame readouts 0.1 ms .. 200 ms (log grid) x offsets and thresholds in proportion to
        the table's exposures and pulse widths, for the parameters the model has."""
        exposure = float(np.median(self.exposure_s))
        shorter = float(np.median(np.minimum(self.exposure_s, self.duty / self.frequency_hz)))
        axes = {
            "row_time_s": np.geomspace(specs[0].low, specs[0].high, 20)[1:-1],
            "integration_offset_s": exposure * np.array([0.0, 0.1, 0.3, 0.6, 1.0]),
            "threshold_s": shorter * np.array([0.01, 0.03, 0.1, 0.2, 0.4, 0.7, 1.0]),
            "noise_s": shorter * np.array([0.03, 0.3]),
        }
        names = [p.name for p in specs]
        bounds = {p.name: (p.low, p.high) for p in specs}
        mesh = np.meshgrid(*(axes[n] for n in names), indexing="ij")
        grid = {n: np.clip(m.ravel(), *bounds[n]) for n, m in zip(names, mesh, strict=True)}
        return grid

    def null_values(self, effect: str) -> dict[str, float]:
        """Parameter values at which an extension reduces to the model without it ({} = a change of form)."""
        return {
            "integration_offset": {"integration_offset_s": 0.0},
            "detection_threshold": {"threshold_s": 0.0},
            "detection_noise": {"noise_s": 0.0},
            "phase_drift": dict.fromkeys(self.drift_names, 0.0),
        }.get(effect, {})

    def item_squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.residual(fit, items) ** 2, np.ones(len(items))

    def predict_fit(self, fit: Fit, items: np.ndarray) -> np.ndarray:
        return self.predict(fit.effects, fit.params, items, fit.extra.get("frames", "lit")).numpy()

    def residual(self, fit: Fit, items: np.ndarray) -> np.ndarray:
        return self.predict_fit(fit, items) - self.rows[items]

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        residual = self.residual(fit, items)
        return float(np.sum(residual**2)), len(items)

    def residual_sample(self, fit: Fit, items: np.ndarray, rng: np.random.Generator) -> ResidualSample:
        """One residual (rows) per table row, against every setting a missing cause could follow: laser
        frequency, exposure, duty cycle, pulse on-time (duty / frequency), the predicted row count, and - when the
        model has a row time - the readout-aliasing phase, the fractional part of the number of laser periods in
        one frame readout (``f x row time x height``): frames whose readout is not a whole number of periods see
        stripes drift and their count alternate, a dependence the phase-averaged model has only on average."""
        residual = self.residual(fit, items)
        on_time = self.duty[items] / self.frequency_hz[items]
        covariates = {
            "frequency_hz": self.frequency_hz[items],
            "exposure_s": self.exposure_s[items],
            "duty": self.duty[items],
            "on_time_s": on_time,
            "predicted_rows": self.predict_fit(fit, items),
        }
        if "row_time_s" in fit.params:
            periods = self.frequency_hz[items] * fit.params["row_time_s"] * self.image_height
            covariates["readout_aliasing_phase"] = periods - np.floor(periods)
        return ResidualSample(
            [np.array([r]) for r in residual],
            {name: [np.array([v]) for v in values] for name, values in covariates.items()},
        )

    # -- reporting -----------------------------------------------------------------------------------------
    def item_label(self, item: int) -> str:
        """A table row by its settings, and its frames' spread next to the table's median when the table has it
        (frames that disagree far more than the rest: a stripe cut by the frame's edge in part of them)."""
        label = (
            f"row {item} ({self.frequency_hz[item]:g} Hz, exposure {self.exposure_setting[item]:g}, "
            f"duty {100 * self.duty[item]:g}%"
        )
        if self.spread is not None:
            label += (
                f", frames' spread {self.spread[item]:.3g} rows against the table's median "
                f"{np.median(self.spread):.3g}"
            )
        return label + ")"

    def analyse(self, fit: Fit, items: np.ndarray) -> dict:
        residual = self.residual(fit, items)
        on = self.duty[items] / self.frequency_hz[items]
        return {
            "exposure_s": binned_rmse(self.exposure_s[items], residual),
            "duty": binned_rmse(self.duty[items], residual),
            "frequency_hz": binned_rmse(self.frequency_hz[items], residual),
            "signed_residual_vs_on_plus_exposure_s": {
                "x": (on + self.exposure_s[items]).tolist(),
                "residual": residual.tolist(),
            },
        }

    def evidence(self, effect: str, before: Fit, after: Fit, items: np.ndarray) -> str:
        res = self.residual(before, items)
        on = self.duty[items] / self.frequency_hz[items]
        drivers = {
            "exposure_overlap": on + self.exposure_s[items],
            "integration_offset": self.exposure_s[items],
            "detection_threshold": np.minimum(on, self.exposure_s[items]),
            "detection_noise": np.minimum(on, self.exposure_s[items]),
            # drift cuts wide stripes: the locked model errs on them
            "phase_drift": on + self.exposure_s[items],
            # from the entry, drift cuts only the stripes that nearly fill the frame
            "drift_from_entry": on + self.exposure_s[items],
        }
        driver = drivers[effect]
        corr = float(np.corrcoef(driver, res)[0, 1]) if np.std(driver) > 0 and np.std(res) > 0 else 0.0
        return (
            f"before {effect}: residual mean {np.mean(res):+.1f} rows, correlation with its driving variable "
            f"{corr:+.2f}"
        )

    def drift_offer(self) -> tuple[bool, str]:
        """Whether selection is offered ``phase_drift`` (and ``drift_from_entry`` on it), and why (or why not)."""
        rows = f"{self.rows_per_recording:.3g} rows per recording ({len(self.drift_names)} recordings)"
        if "interior" not in self.frame_rules:
            return (
                False,
                "a drift starts from whole stripes in view, and --stripe-frames excludes the interior rule",
            )
        if self.rows_per_recording < MIN_ROWS_PER_RECORDING:
            return False, f"{rows}, a recording's drift needs >= {MIN_ROWS_PER_RECORDING}"
        return True, rows

    def derived(self, fit: Fit) -> dict:
        units = {f"unit_source_{k}": v for k, v in self.sources.items()}
        if "row_time_s" not in fit.params:
            return {
                "band_fraction": fit.params["band_rows"] / self.image_height,
                "image_height": self.image_height,
                **units,
            }
        row_time = fit.params["row_time_s"]
        return {
            "row_time_us": row_time * 1e6,
            "frame_readout_ms": row_time * self.image_height * 1e3,
            "integration_offset_us": fit.params.get("integration_offset_s", 0.0) * 1e6,
            "threshold_us": fit.params.get("threshold_s", 0.0) * 1e6,
            "noise_us": fit.params.get("noise_s", 0.0) * 1e6,
            "frames_averaged": fit.extra.get("frames", "lit"),
            "phase_drift_offered": f"{'yes' if self.drift_offered else 'no'}: {self.drift_offer_reason}",
            **(
                {
                    "drifts_locked_for_want_of_evidence": fit.extra["drifts_locked_for_want_of_evidence"],
                    "drift_evidence_rule": (
                        f"a recording keeps its drift when its fit rows' squared error, weighted by each row's "
                        f"variance (standard error of its mean + the model's error beyond it), drops by >= "
                        f"{DRIFT_EVIDENCE} against a lock"
                    ),
                }
                if "drifts_locked_for_want_of_evidence" in fit.extra
                else {}
            ),
            "image_height": self.image_height,
            **units,
        }

    def transform_kwargs(self, fit: Fit) -> dict:
        if "exposure_overlap" not in fit.effects:
            return {}  # the paper's fixed band has nothing the transform takes
        return {
            "model": "rolling_shutter",
            # row time at frame_rows rows; the transform rescales it to its image height (same readout time)
            "row_time_s": fit.params["row_time_s"],
            "frame_rows": self.image_height,
            "integration_offset_s": fit.params.get("integration_offset_s", 0.0),
        }

    def figures(self, base: Fit, extended: Fit, items: np.ndarray, out_dir: Path) -> list[str]:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        x = self.duty * 100
        fig, axes = plt.subplots(1, 2, figsize=(11, 4))
        groups = {(e, f) for e, f in zip(self.exposure_setting, self.frequency_hz, strict=True)}
        for exposure, frequency in sorted(groups)[:12]:
            sel = np.where((self.exposure_setting == exposure) & (self.frequency_hz == frequency))[0]
            sel = sel[np.argsort(x[sel])]
            label = f"exp {exposure:g}, {frequency:g} Hz"
            line = axes[0].plot(x[sel], self.rows[sel], "o", ms=4, label=label)[0]
            axes[0].plot(x[sel], self.predict_fit(extended, sel), "-", color=line.get_color())
        axes[0].axhline(base.params.get("band_rows", np.nan), color="k", ls="--", label="base (fixed band)")
        axes[0].set(xlabel="duty cycle (%)", ylabel="rows lit", title="measured (dots) vs extended (lines)")
        axes[0].legend(fontsize=6)
        for fit, label in ((base, "base"), (extended, "extended")):
            axes[1].plot(self.duty[items] * 100, self.residual(fit, items), "o", label=label)
        axes[1].axhline(0, color="k", lw=0.5)
        axes[1].set(xlabel="duty cycle (%)", ylabel="residual (rows), held-out", title="held-out residuals")
        axes[1].legend()
        fig.tight_layout()
        path = out_dir / "stripes_fit.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        return [path.name]


def line_move_validates(errors: np.ndarray, inside: np.ndarray, stay: int) -> bool:
    """Whether the fit rows, split in ``LINE_MOVE_FOLDS`` seeded folds, predict their own held-out fold better at the
    point of the threshold's flat line that the other folds put lowest than at the fit's own point ``stay``.
    ``errors`` (line points x fit rows) is each row's squared error along the line, ``inside`` whether a point keeps
    the offset in its range. A move that one row alone asks for does not validate where the other rows are predicted
    alike on both flats: the fold holding that row is predicted from rows that cannot tell the flats apart."""
    moved = stayed = 0.0
    for training, validation in kfold(np.arange(errors.shape[1]), LINE_MOVE_FOLDS, LINE_MOVE_SEED):
        training_error = np.where(inside, errors[:, training].sum(1), np.inf)
        # of the points the training rows cannot tell apart, the one nearest the fit's: the least move they ask for
        tied = np.flatnonzero(ties_lowest(training_error, float(np.min(training_error))))
        point = int(tied[np.argmin(np.abs(tied - stay))])
        moved += float(errors[point, validation].sum())
        stayed += float(errors[stay, validation].sum())
    # sums of the same rows' errors in another order can differ by rounding: a move must beat staying by more
    return moved < stayed - abs(stayed) * TIE_SHARE
