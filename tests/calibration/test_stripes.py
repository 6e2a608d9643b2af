"""Stripe tables (laser color strip): units and geometry from the data or required flags, and the rolling-shutter
model against an independent simulator of a second camera.

The simulator below shares no code with ``lerobot_phantom``: it steps the laser waveform on a fine time grid
(square pulses, their exact mean over each step, through a first-order low-pass, i.e. a laser driver with a rise
time the package does not model), integrates it numerically over each row's exposure window for a random pulse
phase per frame, converts it to grey levels with read noise, thresholds, dilates by a blooming spread, applies the
measurement's frame rule and averages the counts over frames. Camera parameters are drawn fresh per run from the
test's own seed, printed on failure (set ``STRIPES_SEED`` to replay a run).
"""

from __future__ import annotations

import functools
import json
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import torch
from scipy.signal import lfilter

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.core import Fit, at_bound, fit_least_squares, kfold, seeded_split
from lerobot_phantom.calibration.stripes import (
    DRIFT_EFFECTS,
    StripeProblem,
    line_move_validates,
    read_stripe_table,
)
from lerobot_phantom.calibration.structure import residual_structure
from lerobot_phantom.transforms import physics

SEED = int(os.environ["STRIPES_SEED"])  # drawn fresh per run by tests/conftest.py
DUTIES = (1, 5, 10, 20, 35, 50)
RECORDING_FRAMES = 24  # frames per video of the drifting tables, written in their recording_frames column


# -- the independent simulator ---------------------------------------------------------------------------------
def simulate_stripe_rows(camera: dict, conditions, rng: np.random.Generator, frames: int) -> np.ndarray:
    """Mean lit-row count per counted frame for each (frequency Hz, duty fraction, exposure s); NaN when the
    frame rule keeps no frame (such a row would not exist in a measured table)."""
    return mean_rows(simulate_stripe_counts(camera, conditions, rng, frames))


def mean_rows(counts: list[list[int]]) -> np.ndarray:
    return np.array([np.mean(c) if c else np.nan for c in counts])


def simulate_stripe_counts(
    camera: dict, conditions, rng: np.random.Generator, frames: int
) -> list[list[int]]:
    """Lit-row count of every frame the frame rule keeps, for each (frequency Hz, duty fraction, exposure s)."""
    kept = []
    for frequency, duty, exposure in conditions:
        counts = []
        for _ in range(frames):
            lit = frame_lit_rows(camera, frequency, duty, exposure, rng.uniform(0.0, 1.0 / frequency), rng)
            count = int(lit.sum())
            if camera["frames"] in ("lit", "interior") and count == 0:
                continue
            if camera["frames"] == "interior" and (lit[0] or lit[-1]):
                continue
            counts.append(count)
        kept.append(counts)
    return kept


def frame_lit_rows(
    camera: dict, frequency: float, duty: float, exposure: float, phase: float, rng: np.random.Generator
) -> np.ndarray:
    """Which rows of one frame read lit, for a pulse train starting ``phase`` seconds into the frame's readout."""
    height, dt = camera["height"], camera["dt"]
    starts = np.arange(height) * camera["row_time"]
    period = 1.0 / frequency
    window = exposure + camera["offset"]
    grid = np.arange(-period, starts[-1] + window + dt, dt)
    # "sampled": the simulator before session 43, kept for the cases found on its tables (pulse_cells says why not)
    if camera["pulses"] == "sampled":
        square = (np.mod(grid - phase, period) < duty * period).astype(float)
    else:
        square = pulse_cells(grid, dt, phase, period, duty * period)
    decay = np.exp(-dt / camera["rise"])
    light = lfilter([1.0 - decay], [1.0, -decay], square)  # one period of lead-in settles the filter
    energy = np.concatenate([[0.0], np.cumsum(light) * dt])
    knots = grid[0] + np.arange(len(energy)) * dt
    collected = np.interp(starts + window, knots, energy) - np.interp(starts, knots, energy)
    grey = camera["gain"] * collected + rng.normal(0.0, camera["read_noise"], height)
    lit = grey >= camera["threshold_grey"]
    spread = camera["spread"]
    if spread:
        padded = np.pad(lit, spread)
        lit = np.any([padded[k : k + height] for k in range(2 * spread + 1)], axis=0)
    return lit


def pulse_cells(grid: np.ndarray, dt: float, phase: float, period: float, on: float) -> np.ndarray:
    """The square pulse train's mean over each cell ``[t, t + dt)`` of the grid: its on-time there over ``dt``.

    Exact for any pulse width. A point sample every ``dt`` (the simulator until session 43) made a pulse last up to
    ``dt`` more or less than drawn, and a row collected a whole number of samples: at 2114 Hz and 1% duty a 4.73 us
    pulse lasted 4 or 6 us, and against a 33.3 us threshold six of them lit 25.0 rows a frame where 0.1 us steps
    light 15.6 and the kernel 15.9 (docs/bench/session43/noise_bloom_3808238891_lit_81fb7d7.txt)."""

    def on_time_until(t: np.ndarray) -> np.ndarray:
        cycles, into = np.divmod(t - phase, period)
        return cycles * on + np.minimum(into, on)

    return (on_time_until(grid + dt) - on_time_until(grid)) / dt


def simulate_drifting_recordings(
    camera: dict,
    condition,
    drift: float,
    rng: np.random.Generator,
    recordings: int,
    frames: int,
    start_at: str = "placement",
) -> np.ndarray:
    """Each recording's mean lit-row count over its frames with a lit row, for one (frequency Hz, duty, exposure
    s): a recording starts at a phase where the frame shows whole stripes (its first and last rows dark, a row
    lit; found by drawing phases until one does), then the laser and frame clocks beat, and the phase advances by
    ``drift`` of a laser period over the recording's ``frames``. With ``start_at="entry"`` the recording starts
    instead at the earliest phase of that run of whole frames (walked back from the drawn phase a row time at a
    time): the first frame to show its stripes whole as they move."""
    frequency, duty, exposure = condition
    period = 1.0 / frequency

    def whole(phase: float) -> bool:
        lit = frame_lit_rows(camera, frequency, duty, exposure, phase, rng)
        return bool(lit.any() and not lit[0] and not lit[-1])

    means = []
    for _ in range(recordings):
        for _ in range(1000):
            start = rng.uniform(0.0, period)
            if whole(start):
                break
        else:
            raise AssertionError(f"no phase shows whole stripes at {condition}")
        if start_at == "entry":
            for step in (8.0 * camera["row_time"], camera["row_time"]):
                while whole(start - step):
                    start -= step
        counts = [
            int(
                frame_lit_rows(
                    camera, frequency, duty, exposure, start + drift * period * k / frames, rng
                ).sum()
            )
            for k in range(frames)
        ]
        means.append(np.mean([c for c in counts if c > 0]))
    return np.array(means)


def draw_camera(rng: np.random.Generator, frames: str) -> dict:
    """A second camera unlike the Logitech: its own height, readout, exposure range (microseconds), laser
    frequencies from below the frame rate (stripes drift, frames miss pulses) to many stripes per frame."""
    height = int(rng.choice([480, 600, 1080]))
    gain = rng.uniform(2e5, 1e6)  # grey levels per second of laser light collected
    return {
        "height": height,
        "row_time": rng.uniform(12e-3, 30e-3) / height,
        "offset": rng.uniform(0.0, 80e-6),
        "rise": rng.uniform(1e-6, 6e-6),
        "gain": gain,
        "threshold_grey": 10.0,
        "read_noise": 1.0,
        "spread": int(rng.integers(0, 3)),
        "frames": frames,
        "dt": 2e-6,
        "pulses": "mean",  # each time step holds the pulse train's exact mean (pulse_cells)
        "frequencies": np.round(np.geomspace(rng.uniform(20, 50), rng.uniform(800, 2500), 5), 1),
        "exposures_us": np.round(np.geomspace(rng.uniform(20, 50), rng.uniform(1000, 3000), 5)),
    }


def write_table(
    path, camera: dict, rng: np.random.Generator, *, n_rows: int, frames: int, style: str
) -> None:
    grid = [(f, d, e) for f in camera["frequencies"] for d in DUTIES for e in camera["exposures_us"]]
    chosen = [grid[i] for i in rng.choice(len(grid), n_rows, replace=False)]
    conditions = [(f, d / 100.0, e * 1e-6) for f, d, e in chosen]
    rows = simulate_stripe_rows(camera, conditions, rng, frames)
    if style == "exposure_us":
        lines = ["frequency,exposure_us,duty_cycle,camera,affected_rows_mean"]
        cell = "{:g}"
    else:  # the Logitech table's layout, the unit only on the command line
        lines = ["frequency,exposure,duty_cycle,camera,affected_rows_mean"]
        cell = "Exposure {:g}"
    for (f, d, e), mean in zip(chosen, rows, strict=True):
        if np.isfinite(mean):
            lines.append(f"{f:g}Hz,{cell.format(e)},{d},SecondCam,{mean:.3f}")
    path.write_text("\n".join(lines) + "\n")


def kernel_against_simulator(seed: int, frames: str, n_frames: int = 300) -> dict:
    """The kernel against the simulator on 12 conditions of a camera drawn for ``seed`` (three frequencies x 5% and
    35% duty x the shortest and the longest exposure), without rise time or read noise (terms the kernel lacks).

    The simulator holds the pulse train's exact mean over each step of ``dt`` (``pulse_cells``) and interpolates
    a row's collected light linearly inside a step, which is off by up to ``dt / 4`` at each end of its window where
    a pulse edge falls inside a step: the kernel is given as the band of its values over on-times ``dt`` apart (it
    matters at a knife edge, where the detection threshold is within ``dt`` of the on-time). The simulated means
    carry their standard error over frames."""
    rng = np.random.default_rng([seed, 1])
    camera = draw_camera(rng, frames) | {"rise": 1e-9, "read_noise": 0.0, "spread": 1}
    conditions = kernel_conditions(camera)
    counts = simulate_stripe_counts(camera, conditions, rng, frames=n_frames)
    f, d, e = (torch.tensor(v) for v in zip(*conditions, strict=True))
    kernel = [
        physics.rolling_shutter_rows_lit(
            f,
            (d + shift * camera["dt"] * f).clamp(0.0, 1.0),
            e,
            camera["row_time"],
            image_rows=camera["height"],
            integration_offset_s=camera["offset"],
            threshold_s=camera["threshold_grey"] / camera["gain"],
            spread_rows=camera["spread"],
            frames=frames,
        ).numpy()
        for shift in (0.0, -1.0, 1.0)
    ]
    return {
        "camera": camera,
        "conditions": conditions,
        "kernel": kernel[0],
        "kernel_low": np.min(kernel, axis=0),
        "kernel_high": np.max(kernel, axis=0),
        "simulated": mean_rows(counts),
        "standard_error": np.array(
            [np.std(c, ddof=1) / np.sqrt(len(c)) if len(c) > 1 else 0.0 for c in counts]
        ),
    }


def shortest_lit_exposure_us(camera: dict) -> float:
    """The shortest exposure whose window, wholly lit, reaches the threshold: on some draws the shortest collects
    too little light to light any row (STRIPES_SEED=3893586369: 25.2 us of window, 32.3 us needed)."""
    return next(
        e
        for e in camera["exposures_us"]
        if e * 1e-6 + camera["offset"] > camera["threshold_grey"] / camera["gain"]
    )


def kernel_conditions(camera: dict) -> list[tuple[float, float, float]]:
    """(frequency Hz, duty fraction, exposure s) of the kernel check: the shortest exposure that can light a row
    (STRIPES_SEED=1316748601 drew 25 us against 31 us needed, which left 3 of 12 conditions with a frame kept under
    the interior rule) and the longest."""
    return [
        (f, d / 100.0, e * 1e-6)
        for f in camera["frequencies"][[0, 2, 4]]
        for d in (5, 35)
        for e in (shortest_lit_exposure_us(camera), camera["exposures_us"][4])
    ]


def kernel_miss(check: dict) -> np.ndarray:
    """Distance of each simulated mean from the kernel's band over its tolerance (> 1 fails; NaN: no frame kept):
    four standard errors of the simulated mean, 3% for the frame-edge approximations of the lit and interior frame
    rules, and 2 rows for integer against continuous rows."""
    simulated = check["simulated"]
    distance = np.maximum(check["kernel_low"] - simulated, simulated - check["kernel_high"]).clip(min=0.0)
    return distance / (4.0 * check["standard_error"] + 0.03 * check["kernel"] + 2.0)


def camera_summary(camera: dict) -> str:
    keys = ("height", "row_time", "offset", "rise", "gain", "spread", "frames", "frequencies", "exposures_us")
    return f"STRIPES_SEED={SEED} camera " + ", ".join(f"{k}={camera[k]}" for k in keys)


def truth_started_fit(problem: StripeProblem, camera: dict, items: np.ndarray, frames: str) -> Fit:
    """Overlap + offset + threshold fitted from the camera's own parameters (blooming counted in the offset: both
    widen every stripe alike), under the camera's frame rule: the minimum the package's first fit must reach."""
    effects = frozenset({"exposure_overlap", "integration_offset", "detection_threshold"})
    truth = {
        "row_time_s": camera["row_time"],
        "integration_offset_s": camera["offset"] + 2 * camera["spread"] * camera["row_time"],
        "threshold_s": camera["threshold_grey"] / camera["gain"],
    }
    target = torch.as_tensor(problem.rows[items])
    params = fit_least_squares(
        problem.param_specs(effects),
        lambda p: problem.predict(effects, p, items, frames) - target,
        warm=truth,
    )
    return Fit(effects, params, {"frames": frames})


def drawn_camera_table(
    path: Path, seed: int, frames: str, style: str = "exposure_us", pulses: str = "mean"
) -> dict:
    """The camera drawn for ``seed`` (and ``frames``), its 60-row stripe table written to ``path``;
    ``pulses="sampled"`` writes the table of the simulator before session 43 (for a case found on it)."""
    rng = np.random.default_rng([seed, 2, len(frames)])
    camera = draw_camera(rng, frames) | {"pulses": pulses}
    write_table(path, camera, rng, n_rows=60, frames=60, style=style)
    return camera


def calibrate_drawn_camera(
    tmp_path, seed: int, frames: str, style: str, calibration_seed: int, pulses: str = "mean", **options
) -> tuple[dict, dict]:
    """(camera, report.json) of ``lerobot-phantom-calibrate`` on the table of ``drawn_camera_table``;
    ``style="exposure"`` leaves the unit off the table, so it is given as a flag; ``options`` are further flags."""
    table = tmp_path / "second_camera.csv"
    camera = drawn_camera_table(table, seed, frames, style, pulses)
    unit = {"exposure_unit_s": 1e-6} if style == "exposure" else {}
    return camera, calibrate_stripes(
        tmp_path, table, camera["height"], seed=calibration_seed, **unit, **options
    )


def calibrate_stripes(tmp_path, table, image_height: int, **options) -> dict:
    """report.json of ``lerobot-phantom-calibrate`` on stripe table ``table``, written under ``tmp_path / "out"``
    (held-out split seed ``SEED % 1000`` unless ``options`` give one)."""
    options.setdefault("seed", SEED % 1000)
    config = CalibrateConfig(
        attack="laser_color_strip",
        measured=str(table),
        out=str(tmp_path / "out"),
        image_height=image_height,
        **options,
    )
    return calibrate(config)


def test_the_drift_and_its_entry_start_are_offered_only_with_enough_rows_per_recording_and_the_interior_rule(
    tmp_path,
):
    """phase_drift is one parameter per recording (a frequency and exposure setting): offered with at least 4 rows per
    recording on average and frames that allow the interior rule; drift_from_entry builds on it and goes with it."""
    table = tmp_path / "sweeps.csv"
    lines = ["frequency,exposure_us,duty_cycle,affected_rows_mean"]
    for exposure in (50, 100):
        lines += [f"25Hz,{exposure},{duty},{10.0 * duty}" for duty in (1, 5, 10, 20)]
    table.write_text("\n".join(lines) + "\n")
    drift = {"phase_drift", "drift_from_entry"}

    def offered(path, frames="auto"):
        problem = StripeProblem(path, image_height=720, exposure_unit_s=None, frames=frames)
        return {e.name for e in problem.candidates} & drift, problem.drift_offer_reason

    assert offered(table) == (drift, "4 rows per recording (2 recordings)")
    names, reason = offered(table, frames="lit")
    assert names == set() and "interior" in reason, reason
    sparse = tmp_path / "sparse.csv"
    sparse.write_text(
        "\n".join(lines[:1] + [line for line in lines[1:] if ",5," not in line and ",20," not in line]) + "\n"
    )
    names, reason = offered(sparse)
    assert names == set() and "2 rows per recording" in reason, reason


# -- the physics kernel against the simulator ---------------------------------------------------------------------
def test_the_simulators_steps_hold_each_pulse_whole_at_any_phase():
    """A pulse shorter than a few time steps (4.73 us at 2114 Hz and 1% duty, on 2 us steps) carries its whole
    on-time into the steps it falls in, at every phase; point samples gave it 4 or 6 us (docs/bench/session43.md)."""
    period, on, dt = 1.0 / 2114.3, 0.01 / 2114.3, 2e-6
    grid = np.arange(0.0, 3 * period, dt)
    fine = np.arange(0.0, grid[-1] + dt, dt / 1000) + dt / 2000  # midpoints of steps a thousand times finer
    for phase in np.random.default_rng(SEED).uniform(0.0, period, 20):
        cells = pulse_cells(grid, dt, phase, period, on)
        assert cells.min() > -1e-9 and cells.max() < 1.0 + 1e-9  # a share of each step, up to rounding
        # the on-time the steps hold up to each third of the grid, against the fine steps' (within two of them)
        for end in (len(grid) // 3, 2 * len(grid) // 3, len(grid)):
            reference = (np.mod(fine[: end * 1000] - phase, period) < on).sum() * dt / 1000
            assert cells[:end].sum() * dt == pytest.approx(reference, abs=dt / 500)


@pytest.mark.parametrize("frames", physics.STRIPE_FRAME_RULES)
def test_phase_averaged_rows_match_the_simulator(frames):
    """Without the unmodelled rise time and noise, the analytic expectation equals the simulated frame mean.

    Until session 23 this was an expected failure on some draws: the kernel bloomed stripes narrower than a row
    time in every frame (102.8 rows against 56.8, STRIPES_SEED=2577942692), and a fixed tolerance of 8% + 4 rows
    was under the simulator's sampling error at low frequencies (406 against 370 rows, STRIPES_SEED=2677795359,
    which 3000 frames bring to 402). Until session 28 the interior rule was: its edge rows were taken H rows apart
    (not H - 1) and dark only if a stripe's bloom beyond the frame missed them, so on a frame whose gap between
    stripes barely holds both edges no frame qualified and the kernel fell back to the lit rule (301.4 against the
    simulator's 285.5 rows, STRIPES_SEED=594202656; 284.7 with the edges right)."""
    check = kernel_against_simulator(SEED, frames)
    miss = kernel_miss(check)
    kept = np.isfinite(miss)
    table = np.c_[check["kernel_low"], check["kernel_high"], check["simulated"], check["standard_error"]]
    assert kept.sum() >= 6, camera_summary(check["camera"])
    assert (miss[kept] <= 1.0).all(), (
        f"{camera_summary(check['camera'])}\nkernel band, simulated, its error\n{table}"
    )


@pytest.mark.parametrize(
    ("on_rows", "period", "frames"),
    [
        (0.2, 7.3, "all"),
        (0.7, 7.3, "all"),
        (2.6, 7.3, "all"),
        (0.2, 500.0, "lit"),
        (2.6, 500.0, "lit"),
        (2.6, 7.3, "interior"),
        (20.0, 60.0, "interior"),
    ],
)
def test_blooming_widens_only_the_stripes_that_light_a_row(on_rows, period, frames):
    """Exact expectation over the pulse phase (a fine phase grid, rows as discrete start times): a stripe narrower
    than a row time lights a row for only part of the phases, and only then blooms (session 23: the kernel added
    the spread to every stripe, 102.8 rows where the simulator counted 56.8). A pulse slower than the readout
    (period 500 rows, 200-row frames) leaves most frames dark; blooming cannot light one, so it does not change
    which frames the ``lit`` rule counts. Under the ``interior`` rule an edge row is dark unless a stripe blooms
    into it from inside the frame (until session 29 the kernel bloomed into it from beyond the edge too: 189.0 rows
    at 2.6 of 7.3, where frames count 186.3)."""
    rows, window, spread = 200, 0.3, 2
    starts = np.arange(rows, dtype=float)  # one row time = 1
    counts = []
    for phase in np.arange(0.0, period, 0.01):
        # a row collects light when its window [t, t + window] overlaps a pulse [phase + k period, + on_rows]
        lit = np.mod(starts - phase + window, period) < on_rows + window
        padded = np.pad(lit, spread)
        bloomed = np.any([padded[k : k + rows] for k in range(2 * spread + 1)], axis=0)
        edges_dark = not bloomed[0] and not bloomed[-1]
        if frames == "all" or (bloomed.any() and (frames == "lit" or edges_dark)):
            counts.append(bloomed.sum())
    assert counts, "no frame kept: the case does not test the rule"
    kernel = physics.rolling_shutter_rows_lit(
        torch.tensor(1.0 / period),
        torch.tensor(on_rows / period),
        torch.tensor(window),
        1.0,
        image_rows=rows,
        spread_rows=spread,
        frames=frames,
    )
    # a stripe at the frame's edge loses the spread edge that falls outside the frame: under one row with 27 stripes
    # per frame, a few hundredths of a row with one stripe in a lit frame
    assert float(kernel) == pytest.approx(np.mean(counts), abs=1.0 if frames == "all" else 0.1)


def test_a_window_that_holds_the_whole_pulse_is_lit_as_a_step_in_the_threshold():
    """Where the window holds the whole pulse, the collected light is flat (a plateau at the on-time): just under the
    on-time that whole plateau is lit, and the lit time's slope in the threshold is the stripe's two edges, -2. Until
    session 29 the plateau's share divided by a clamped width of 1e-15 s: a tenth of the plateau lit and a slope of
    -3e12 there, a Jacobian that froze a fit's threshold at a pulse's on-time."""
    period, on, window = (torch.tensor(v, dtype=torch.float64) for v in (1e-2, 2e-3, 5e-3))
    threshold = (on - 1e-16).requires_grad_(True)
    lit = physics.pulse_overlap_lit_time(period, on, window, threshold)
    (slope,) = torch.autograd.grad(lit, threshold)
    assert float(lit) == pytest.approx(float(window - on), rel=1e-9)
    assert float(slope) == pytest.approx(-2.0)
    assert float(physics.pulse_overlap_lit_time(period, on, window, on + 1e-12)) == 0.0


def test_lit_time_is_the_overlap_minus_twice_the_threshold():
    period, on, window = torch.tensor(1e-2), torch.tensor(2e-3), torch.tensor(5e-4)
    assert float(physics.pulse_overlap_lit_time(period, on, window)) == pytest.approx(2.5e-3)
    assert float(physics.pulse_overlap_lit_time(period, on, window, 1e-4)) == pytest.approx(2.3e-3)
    assert (
        float(physics.pulse_overlap_lit_time(period, on, window, 6e-4)) == 0.0
    )  # more than a window collects
    # a window longer than the gap between pulses always collects light: every row is lit
    assert float(
        physics.pulse_overlap_lit_time(period, torch.tensor(9e-3), torch.tensor(2e-3))
    ) == pytest.approx(1e-2)
    with pytest.raises(ValueError, match="valid: all, lit, interior"):
        physics.rolling_shutter_rows_lit(period, on, window, 1e-5, image_rows=10, frames="every")


@pytest.mark.parametrize(
    ("seed", "frames"),
    [
        (3, "lit"),
        (2677795359, "lit"),
        (2, "interior"),
        (6, "interior"),
        (22, "lit"),
        (24, "interior"),
        (22, "interior"),
    ],
)
def test_the_first_fit_finds_the_stripe_count_regime_of_the_camera(tmp_path, seed, frames):
    """Draws on which the fit once stopped in another stripe-count regime (a row time 2-5.4x off, fit RMSE 5-24x
    the one reached from the camera's own parameters; seeds 3, 2677795359, 2, 6) or, at the right row time, in
    another offset/threshold minimum because it started from one grid point per row time (seeds 22, 24: 3-8x), or
    in another threshold regime, on the far side of a pulse's on-time (seed 24 interior once the interior rule's
    edges were right: 7.4 rows against 1.3; seed 22 interior: 3.3 against 0.8): the fit must reach the minimum the
    truth reaches."""
    table = tmp_path / "table.csv"
    camera = drawn_camera_table(table, seed, frames)
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    items = np.arange(problem.n_items)
    from_truth = truth_started_fit(problem, camera, items, frames)
    fitted = problem.fit(from_truth.effects, items)

    def rmse(fit):
        return float(np.sqrt(np.mean(problem.residual(fit, items) ** 2)))

    assert rmse(fitted) <= 1.1 * rmse(from_truth) + 0.5, (
        f"{camera_summary(camera)}\nfitted {fitted.params} {fitted.extra}: {rmse(fitted):.2f} rows; "
        f"from the camera's parameters {from_truth.params}: {rmse(from_truth):.2f} rows"
    )


@pytest.mark.xfail(
    strict=True,
    reason="open (issue 12): row-time starts 49% apart leave three of four folds a stripe-count regime off. 58 starts "
    "at the error profile's local minima, at least 1.49x apart, fixed every fold (CV 15.8 -> 4.0 rows) and seed 6 "
    "interior above, but over 42 drawn cases the 30-row bar went from 6 to 8 misses (4111198912 lit: 2.86 -> 341 "
    "rows), and an edge minimum at the grid's low bound took a small table's row time to its bound: taken back in "
    "session 48 (docs/bench/session48.md)",
)
def test_every_fold_fit_reaches_the_cameras_readout(tmp_path):
    """The suite's draw of session 47 (STRIPES_SEED=3503845322, interior frames): on the training rows of each of
    the selection's four folds the offset model should reach the camera's row time under its frame rule. The
    interior rule's search stops at 20.1-20.7 us (34-38 rows RMSE) on three folds, which take the "lit" rule at
    12.9-14.4 us (29-34 rows), where 22.2 us fits within 4-8 rows. In the selection two folds do so:
    cross-validation scores every extension on their misfit (docs/bench/session48.md)."""
    seed, frames = 3503845322, "interior"
    table = tmp_path / "table.csv"
    camera = drawn_camera_table(table, seed, frames)
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    fit_items, _ = seeded_split(problem.n_items, 0.2, seed % 1000)
    effects = frozenset({"exposure_overlap", "integration_offset"})
    for fold, (train, _) in enumerate(kfold(fit_items, 4, seed % 1000 + 1, 2500)):
        fit = problem.fit(effects, train)
        about = f"{camera_summary(camera)}\nfold {fold}: {fit.params} {fit.extra}"
        assert fit.extra["frames"] == frames, about
        assert fit.params["row_time_s"] == pytest.approx(camera["row_time"], rel=0.02), about


@pytest.mark.parametrize("factor", [0.5, 2.0, 4.0])
def test_a_bootstrap_refit_searches_the_regimes_again(tmp_path, factor):
    """A bootstrap refit starts from the estimate. Started in another stripe-count regime (the row time a factor
    off), it must reach the regime that fits the rows, as the estimator's own search does: refits kept in the
    start's regime made the row time's interval that regime's width (the Logitech table: 47.8-48.9 us, where a
    4x readout fits as well)."""
    rng = np.random.default_rng([SEED, 5])
    camera = draw_camera(rng, "interior")
    table = tmp_path / "table.csv"
    write_table(table, camera, rng, n_rows=60, frames=60, style="exposure_us")
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    items = np.arange(problem.n_items)
    effects = frozenset({"exposure_overlap", "integration_offset"})
    estimate = problem.fit(effects, items)
    moved = {**estimate.params, "row_time_s": estimate.params["row_time_s"] * factor}
    refit = problem.fit(effects, items, start=Fit(effects, moved, dict(estimate.extra)))

    def rmse(fit):
        return float(np.sqrt(np.mean(problem.residual(fit, items) ** 2)))

    about = f"{camera_summary(camera)}\nestimate {estimate.params} {rmse(estimate):.2f} rows, refit {refit.params}"
    assert rmse(refit) <= 1.02 * rmse(estimate) + 0.1, about


def test_rows_that_fix_no_row_time_do_not_leave_it_at_a_bound(tmp_path):
    """Drawn camera 1095341462 (lit frames, the second-camera test's table and split): with read noise in the model
    the fit rows fix no row time (fits from every start match to 1e-6), and the fit kept the one a start had left
    at 0.37 us, within 0.1% of the range's low bound. Identification then rejected exposure_overlap for it and the
    base model was written (178 rows held-out, against 3.0). Among equal fits none at a bound is kept."""
    seed, frames = 1095341462, "lit"
    table = tmp_path / "table.csv"
    camera = drawn_camera_table(table, seed, frames)
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    fit_items, _ = seeded_split(problem.n_items, 0.2, seed % 1000)
    effects = frozenset({"exposure_overlap", "integration_offset", "detection_threshold", "detection_noise"})
    fit = problem.fit(effects, fit_items)
    at_bounds = [p.name for p in problem.param_specs(effects) if at_bound(fit.params[p.name], p.low, p.high)]
    assert not at_bounds, f"{camera_summary(camera)}\n{fit.params} {fit.extra}: {at_bounds} at a bound"


BRACKETED_NOISE_ROWS = 3.0


def bracketed_threshold_table(
    path: Path, rng: np.random.Generator, exposures_us: tuple[float, ...] = (79, 246, 765)
) -> dict[str, float]:
    """A lit-frames table whose pulses bracket the camera's threshold: 18.75 us pulses (533.2 Hz, 1%) collect less
    than it, 48.05 us ones (208.1 Hz, 1%) more, and no window collects an amount between (none is that short, and
    none holds two of the short pulses; a longer exposure in ``exposures_us`` adds such steps). Rows from the
    package's own kernel plus Gaussian noise: what is tested is the fit, not the model."""
    truth = {"row_time_s": 15e-6, "integration_offset_s": 10e-6, "threshold_s": 30e-6}
    conditions = [
        (frequency, duty, exposure)
        for frequency in (31.7, 208.1, 533.2, 1040.0)
        for duty in (1, 5, 20, 50)
        for exposure in exposures_us
    ]
    frequency, duty, exposure = (torch.tensor(c, dtype=torch.float64) for c in zip(*conditions, strict=True))
    rows = physics.rolling_shutter_rows_lit(
        frequency,
        duty / 100,
        exposure * 1e-6,
        truth["row_time_s"],
        image_rows=1080,
        integration_offset_s=truth["integration_offset_s"],
        threshold_s=truth["threshold_s"],
        frames="lit",
    ).numpy()
    rows = rows + rng.normal(0.0, BRACKETED_NOISE_ROWS, len(rows))
    lines = ["frequency,exposure_us,duty_cycle,image_height,affected_rows_mean"]
    lines += [f"{f},{e},{d},1080,{r:.3f}" for (f, d, e), r in zip(conditions, rows, strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return truth


def fit_from_threshold_start(
    tmp_path: Path,
    rng: np.random.Generator,
    start_threshold_us: float,
    exposures_us: tuple[float, ...] = (79, 246, 765),
) -> tuple[dict[str, float], StripeProblem, Fit]:
    """(truth, problem, fit) of threshold + offset on every row of a ``bracketed_threshold_table``, started from the
    truth moved along the line the error is flat on: the threshold at ``start_threshold_us``, the offset moved twice
    as far (every stripe keeps its width)."""
    truth = bracketed_threshold_table(tmp_path / "table.csv", rng, exposures_us)
    problem = StripeProblem(tmp_path / "table.csv", image_height=None, exposure_unit_s=None)
    effects = frozenset({"exposure_overlap", "integration_offset", "detection_threshold"})
    moved = start_threshold_us * 1e-6 - truth["threshold_s"]
    start = {
        **truth,
        "threshold_s": start_threshold_us * 1e-6,
        "integration_offset_s": truth["integration_offset_s"] + 2 * moved,
    }
    return (
        truth,
        problem,
        problem.fit(effects, np.arange(problem.n_items), Fit(effects, start, {"frames": "lit"})),
    )


@pytest.mark.parametrize("start_threshold_us", [20.0, 46.0])
def test_a_threshold_the_fit_rows_bracket_is_fitted_to_its_floor_whatever_the_start(
    tmp_path, start_threshold_us
):
    """The fit rows show the 18.75 us pulses dark and the 48.05 us ones lit: every threshold between gives every row
    the same count, with the offset moving twice as far to keep the widths. A fit must not stop where its start left
    it (a selection fold of drawn camera 531200696 stopped at 46.5 us and darkened the 36.6 us pulses it validated,
    61.8 rows against 3.5): from a start near either end it ends at the flat's floor, just above 18.75 us (within
    the flat's grid step), and keeps the widths the rows measure."""
    truth, problem, fit = fit_from_threshold_start(
        tmp_path, np.random.default_rng([SEED, 52]), start_threshold_us
    )
    darkest_lit, brightest_dark = 0.01 / 208.1, 0.01 / 533.2
    width_error = width_standard_error_s(problem, fit)
    about = (
        f"STRIPES_SEED={SEED} start {start_threshold_us} us: {fit.params} {fit.extra}, width standard error "
        f"{width_error * 1e6:.3f} us"
    )
    assert fit.extra["frames"] == "lit", about
    assert brightest_dark < fit.params["threshold_s"] <= 1.02 * brightest_dark < darkest_lit, about
    width = fit.params["integration_offset_s"] - 2 * fit.params["threshold_s"]
    truth_width = truth["integration_offset_s"] - 2 * truth["threshold_s"]
    assert width == pytest.approx(truth_width, abs=5 * width_error), about


def width_standard_error_s(problem: StripeProblem, fit: Fit) -> float:
    """The standard error of the stripes' width (offset - 2 x threshold) that rows with the table's noise give, by
    least squares linearised at ``fit`` over row time and offset (the threshold held: its flat leaves the rows
    unchanged). A fixed 2 us bound failed 2.0% of 150 fresh draws, whose spread (0.809 us) this matches
    (docs/bench/session82/bracket_width_spread.txt)."""
    items = np.arange(problem.n_items)

    def slope(name: str, step: float) -> np.ndarray:
        moved = [
            Fit(fit.effects, {**fit.params, name: fit.params[name] + h}, fit.extra) for h in (step, -step)
        ]
        return (problem.residual(moved[0], items) - problem.residual(moved[1], items)) / (2 * step)

    jacobian = np.stack([slope("row_time_s", 1e-9), slope("integration_offset_s", 1e-8)], axis=1)
    covariance = BRACKETED_NOISE_ROWS**2 * np.linalg.inv(jacobian.T @ jacobian)
    return float(np.sqrt(covariance[1, 1]))


def assert_at_the_floor_above_three_short_pulses(
    truth: dict[str, float], problem: StripeProblem, fit: Fit
) -> None:
    """A multi-pulse table's fit under the lit rule ended at the floor of the 28.85-37.5 us flat (just above the light
    of three 9.62 us pulses, within the flat's grid step) with at most 1.5x the truth's squared error."""
    items = np.arange(problem.n_items)
    three_short_pulses = 3 * 0.01 / 1040.0
    about = f"STRIPES_SEED={SEED}: {fit.params} {fit.extra}"
    assert fit.extra["frames"] == "lit", about
    assert three_short_pulses < fit.params["threshold_s"] <= 1.02 * three_short_pulses, about
    truth_error = float(np.sum(problem.residual(Fit(fit.effects, truth, {"frames": "lit"}), items) ** 2))
    assert float(np.sum(problem.residual(fit, items) ** 2)) <= 1.5 * truth_error, about


@pytest.mark.xfail(
    strict=True,
    reason="open (issue 12): one fit row witnesses this step (533.2 Hz, 1%, 2375 us: 294.8 rows measured, none on "
    "the 37.5-48.05 us flat), and the fit moves along its flat line only where the move validates across the fit "
    "rows' folds, which one row's evidence cannot (docs/bench/session54.md). Moving on any lower error (4e18abf) "
    "passes this test but fails drawn camera 4111198912 lit (sampled pulses), where two selection folds moved on "
    "the evidence of one inner fold's rows (6433 -> 2406 in squared error), validated worse (8.03 -> 9.87 rows) "
    "and the overlap alone was written, 2.80 -> 340.66 rows held-out (docs/bench/session53.md). Whether a row this "
    "far outside the read noise should move a fit alone is open",
)
def test_a_threshold_beyond_a_step_of_several_pulses_in_one_window_is_reached(tmp_path):
    """A 2375 us exposure added to the bracketed table: its windows hold two 18.75 us pulses (37.5 us of light) and
    three 9.62 us ones (28.85 us), steps that no single pulse makes. A fit started at 46 us stops on the 37.5-48.05 us
    flat, where the long window's rows lose light the camera's 30 us threshold keeps; it must cross to the 28.85-37.5
    us flat, whose error is far lower, and end at that flat's floor."""
    truth, problem, fit = fit_from_threshold_start(
        tmp_path, np.random.default_rng([SEED, 53]), 46.0, exposures_us=(79, 246, 765, 2375)
    )
    assert_at_the_floor_above_three_short_pulses(truth, problem, fit)


def test_a_move_along_the_flat_line_validates_only_on_rows_of_several_folds():
    """``line_move_validates`` on made-up errors of 12 rows along a line of 5 points, the fit at point 3, point 1 the
    lowest: rows that ask for the move in every fold validate it; the same gain carried by one row does not (its fold
    is predicted from rows that cannot tell the points apart); neither does a gain within rounding, nor a point
    outside the offset's range."""
    n_points, n_rows, stay = 5, 12, 3
    everywhere = np.ones(n_points, bool)
    every_row = np.full((n_points, n_rows), 6.0)
    every_row[1] = 1.0  # each row predicted better at point 1 than at the fit's point
    assert line_move_validates(every_row, everywhere, stay)
    one_row = np.ones((n_points, n_rows))
    one_row[[0, 2, 3, 4], 7] += 60.0  # only row 7 sets point 1 apart, by as much as all rows did above
    assert not line_move_validates(one_row, everywhere, stay)
    rounding = np.ones((n_points, n_rows))
    rounding[stay] += 1e-12
    assert not line_move_validates(rounding, everywhere, stay)
    outside = everywhere.copy()
    outside[1] = False
    assert not line_move_validates(every_row, outside, stay)


def test_a_step_of_several_pulses_that_several_fit_rows_witness_is_crossed(tmp_path):
    """Exposures of 2375 and 2900 us added to the bracketed table: windows holding two 18.75 us pulses (37.5 us of
    light) or four 9.62 us ones (38.46 us), three rows that the camera's 30 us threshold shows lit and any threshold
    above 38.46 us shows dark. A fit started at 46 us stops on the 38.46-48.05 us flat; the move along its flat line
    to the 28.85-37.5 us flat is asked for by rows in more than one fold, so it validates, and the fit ends at that
    flat's floor with the truth's error (fails at f1bd86b: 38.63 us, squared error ~4e5 against the truth's ~700)."""
    truth, problem, fit = fit_from_threshold_start(
        tmp_path, np.random.default_rng([SEED, 54]), 46.0, exposures_us=(79, 246, 765, 2375, 2900)
    )
    assert_at_the_floor_above_three_short_pulses(truth, problem, fit)


@pytest.mark.parametrize("start_at", ["placement", "entry"])
@pytest.mark.parametrize("drift", [0.1, 0.4])
def test_a_drifting_recording_matches_the_simulator(drift, start_at):
    """A laser at the frame rate (phase locked, placed with whole stripes in view: anywhere, or where they just came
    whole into view) whose clock beats with the camera's by ``drift`` of a period per recording: the kernel's
    expectation over placements equals the simulated recordings' mean, for a stripe that fills most of the frame
    (cut at the edges) and a narrow one. From the entry, the narrow stripe is not cut by the larger drift, which
    crosses less than the frame's free span; from anywhere it is."""
    rng = np.random.default_rng([SEED, 6])
    camera = draw_camera(rng, "interior") | {"rise": 1e-9, "read_noise": 0.0, "spread": 0, "dt": 4e-6}
    readout = camera["height"] * camera["row_time"]
    frequency = 1.0 / (2.0 * readout)  # one stripe per frame, a period of two readouts
    exposure = shortest_lit_exposure_us(camera) * 1e-6
    for duty in (0.4, 0.05):
        condition = (frequency, duty, exposure)
        means = simulate_drifting_recordings(
            camera,
            condition,
            drift,
            rng,
            recordings=60 if start_at == "placement" else 6,
            frames=RECORDING_FRAMES,
            start_at=start_at,
        )
        interior_rows = functools.partial(
            physics.rolling_shutter_rows_lit,
            torch.tensor([frequency]),
            torch.tensor([duty]),
            torch.tensor([condition[2]]),
            camera["row_time"],
            image_rows=camera["height"],
            integration_offset_s=camera["offset"],
            threshold_s=camera["threshold_grey"] / camera["gain"],
            frames="interior",
        )
        kernel = interior_rows(
            drift=torch.tensor([drift]), drift_start=start_at, recording_frames=RECORDING_FRAMES
        )
        locked = interior_rows()
        error = 4.0 * means.std(ddof=1) / np.sqrt(len(means)) + 0.005 * float(kernel) + 1.0
        about = (
            f"{camera_summary(camera)} duty {duty} drift {drift} from {start_at}: kernel {float(kernel):.1f} "
        )
        about += f"(locked {float(locked):.1f}), simulated {means.mean():.1f} +- "
        about += f"{means.std(ddof=1) / np.sqrt(len(means)):.1f}"
        assert abs(float(kernel) - means.mean()) <= error, about
        if (
            duty == 0.4 and drift == 0.4
        ):  # a wide stripe cut this much: the simulation tells drift from a lock
            assert float(locked) - means.mean() > error, about
        if duty == 0.05 and drift == 0.4:
            cut = float(locked) - means.mean()
            standard_error = means.std(ddof=1) / np.sqrt(len(means))
            assert (cut < 1.0) if start_at == "entry" else (cut > 4.0 * standard_error + 1.0), about


def drifting_table(
    path, camera: dict, rng: np.random.Generator, drifts: np.ndarray, start_at: str = "placement"
) -> None:
    """A duty sweep per exposure setting at a laser near the frame rate (one stripe per frame, a period of two
    readouts): each row is one recording of ``RECORDING_FRAMES`` frames, whose phase drifts by ``drifts[k]`` of a
    period at the k-th exposure (0: locked)."""
    frequency = round(1.0 / (2.0 * camera["height"] * camera["row_time"]), 1)
    lines = ["frequency,exposure_us,duty_cycle,affected_rows_mean,recording_frames"]
    for exposure, drift in zip(camera["exposures_us"], drifts, strict=True):
        for duty in (2, 5, 10, 15, 20, 25, 30, 35):
            condition = (frequency, duty / 100.0, exposure * 1e-6)
            mean = simulate_drifting_recordings(
                camera, condition, drift, rng, recordings=1, frames=RECORDING_FRAMES, start_at=start_at
            )[0]
            lines.append(f"{frequency:g}Hz,{exposure:g},{duty},{mean:.3f},{RECORDING_FRAMES}")
    path.write_text("\n".join(lines) + "\n")


def drifting_draw(seed: int, drifting: bool) -> tuple[np.random.Generator, dict, np.ndarray]:
    """The drift-naming tests' draw for ``seed``: (its generator, which draws the table next; the camera; each
    recording's drift), two of five recordings drifting a third to two thirds of a period (none unless
    ``drifting``). Every start draws the same camera and drifts."""
    rng = np.random.default_rng([seed, 7])
    camera = draw_camera(rng, "interior")
    drifts = np.zeros(5)
    if drifting:
        drifts[rng.choice(5, 2, replace=False)] = rng.uniform(0.33, 0.67, 2)
    return rng, camera, drifts


@pytest.fixture(scope="module")
def drift_reports(tmp_path_factory) -> Callable[[str | None], tuple[dict, str, dict, Path]]:
    """(report.json, failure message, camera, table) of the calibration on the drifting table of a start
    (``None``: every recording locked), computed once per module (two tests read them)."""
    reports: dict = {}

    def report_for(start_at: str | None) -> tuple[dict, str, dict, Path]:
        if start_at not in reports:
            rng, camera, drifts = drifting_draw(SEED, drifting=start_at is not None)
            out = tmp_path_factory.mktemp(f"drift_{start_at}")
            table = out / "drifting.csv"
            drifting_table(table, camera, rng, drifts, start_at=start_at or "placement")
            # bootstrap=10: the suite's budget, a third of the default draws behind each parameter's interval
            report = calibrate_stripes(out, table, camera["height"], bootstrap=10)
            about = f"{camera_summary(camera)} drifts {drifts} from {start_at}\nnamed "
            about += f"{sorted(f['effect'] for f in report['findings'])}\n{report['selection']['steps']}"
            reports[start_at] = (report, about, camera, table)
        return reports[start_at]

    return report_for


@pytest.mark.slow
@pytest.mark.sampled
@pytest.mark.parametrize(
    "start_at",
    [
        pytest.param("placement", id="two recordings drift"),
        pytest.param("entry", id="two recordings drift from the entry"),
        pytest.param(
            None,
            id="null: locked",
            marks=pytest.mark.xfail(
                strict=False,
                reason="open (issue 12): failed once in session 29's review on a seed whose output was cut "
                "(phase_drift named on locked recordings, or the overlap not named: the message was lost); 0 of 20 "
                "seeds 101-120 fail at 582cfc5 and at ecaf039 (docs/bench/session29/drift_null_seeds_*); seed 12 "
                "fails at fab577e, 4765c93 and 921312e: at its shortest exposure a fully lit row reads 11 grey "
                "against a threshold of 10 with a read noise of 1, so rows inside the stripe drop out and "
                "blooming refills all but runs of three; the kernel's soft threshold has no refill, and a drift "
                "takes the misfit (docs/bench/session34.md, section 9)",
            ),
        ),
    ],
)
def test_recordings_that_drift_are_named_and_locked_ones_are_not(drift_reports, start_at):
    """Two of five recordings drift by a third to two thirds of a period (the rest are locked): phase_drift is
    named, a drifting recording's interval excludes 0 and the held-out rows are predicted better than by the locked
    model; drift_from_entry is named where the simulated recordings start as their stripes come whole into view
    (where they start at any whole placement, see the next test); with every recording locked, phase_drift is not
    named."""
    report, about, camera, table = drift_reports(start_at)
    named = {f["effect"] for f in report["findings"]}
    assert "exposure_overlap" in named, about
    if start_at is None:
        assert "phase_drift" not in named, about
        return
    withdrawn_drift = [w for w in report["selection"]["withdrawn"] if w["effect"] == "phase_drift"]
    if "phase_drift" not in named and withdrawn_drift:
        pytest.xfail(
            "open (issue 12), test_a_drift_the_locked_readout_hides_is_found: phase_drift was selected, then "
            f"withdrawn ({withdrawn_drift[0]['reasons']}). Seen on STRIPES_SEED=1233088577: threshold + drift "
            "cross-validated at 21.67 rows, where threshold + drift + read noise, the noise at its bound 0 in 4 of 4 "
            "folds, scored 6.86: the drift fits ended elsewhere (docs/bench/session53.md)"
        )
    assert "phase_drift" in named, about
    if start_at == "entry":
        assert "drift_from_entry" in named, about
    intervals = report["extended"]["param_intervals"]
    drifted = [k for k in intervals if k.startswith("drift_") and intervals[k]["low"] > 0.05]
    assert drifted, about
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    fit_items, heldout = seeded_split(problem.n_items, 0.2, SEED % 1000)
    locked = problem.fit(frozenset(report["extended"]["effects"]) - set(DRIFT_EFFECTS), fit_items)
    locked_rmse = problem.rmse(locked, heldout)
    if report["extended"]["heldout_rmse"] >= locked_rmse:
        _, _, drifts = drifting_draw(SEED, drifting=True)
        truth = dict(zip(camera["exposures_us"], drifts, strict=True))
        drifts = np.array(
            [truth[problem.exposure_setting[problem.recording == k][0]] for k in range(len(drifts))]
        )
        fitted = np.array([report["extended"]["params"][name] for name in problem.drift_names])
        if np.any((drifts > 0) & (fitted == 0.0)):
            pytest.xfail(
                "open (issue 12), test_a_drift_the_locked_readout_hides_is_found: a drifting recording's drift was "
                f"left at 0 (truth {drifts}, fitted {fitted}); held-out {report['extended']['heldout_rmse']:.2f} "
                f"rows against the locked model's {locked_rmse:.2f}"
            )
    assert report["extended"]["heldout_rmse"] < locked_rmse, about


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="open (issue 12): the drift fit grids each recording's drift once, at the locked model's readout, which "
    "the drifting recordings bias; a recording the grid leaves at 0 stays there. Grid again at the joint fit's "
    "readout (tried in session 38, e8f7105) finds it, but on the Axis table it also gave two locked sweeps drifts "
    "from one video each (splits 3 and 6: 3.21 -> 6.42 and 2.82 -> 6.23 rows held-out), named drift_from_entry on "
    "a placement table (STRIPES_SEED=1010) and cost 1.1-2.5x the CPU; requiring two videos' evidence (3874924) "
    "undid split 2 (3.95 -> 26.4) and a placement draw. Both were taken back (docs/bench/session38.md)",
)
def test_a_drift_the_locked_readout_hides_is_found(tmp_path):
    """A draw of the entry-drift test (STRIPES_SEED=1002: drifts of 0.37 and 0.55 of a period at the first and fourth
    exposures) on which the locked model, fitted first, meets the cut stripes with a row time 8% long. At that
    readout the first recording's fit rows are predicted best locked, so the grid sets its drift to 0; the joint fit
    then moves the row time to the truth and leaves that drift at 0 (up to a quarter of a period it cuts none of the
    recording's fit stripes: no slope), and the widest held-out stripes are predicted 44 and 75 rows too wide
    (held-out 30.8 rows against the locked model's 24.9, which fails the entry-drift test)."""
    rng, camera, drifts = drifting_draw(1002, drifting=True)
    table = tmp_path / "drifting.csv"
    drifting_table(table, camera, rng, drifts, start_at="entry")
    problem = StripeProblem(table, image_height=camera["height"], exposure_unit_s=None)
    fit_items, heldout = seeded_split(problem.n_items, 0.2, 1002 % 1000)
    fit = problem.fit(frozenset({"exposure_overlap", "phase_drift", "drift_from_entry"}), fit_items)
    found = np.array([fit.params[name] for name in problem.drift_names])
    about = (
        f"drifts {drifts}, found {found}, row time {fit.params['row_time_s']} (truth {camera['row_time']})"
    )
    assert np.all(np.abs(found - drifts)[drifts > 0] < 0.1), about
    assert problem.rmse(fit, heldout) < 5.0, about


def gain_interval(report: dict, effect: str) -> tuple[float, float] | None:
    """The interval of the cross-validated error ratio on which ``effect`` was identified (None: not named)."""
    for result in report["identification"]:
        if result["effect"] == effect and result["identified"]:
            return result["validation_ratio"]["low"], result["validation_ratio"]["high"]
    return None


@pytest.mark.slow
@pytest.mark.sampled
def test_the_entry_start_is_told_from_any_whole_placement(drift_reports):
    """The same camera and drifts, the recordings starting at any whole placement against starting as their
    stripes come whole into view: drift_from_entry is named on the entry table, and on the placement table it is
    not named or named on a gain whose interval lies wholly below the entry table's. Not named is not asserted on
    its own: selection names an effect whose gain has a 90% interval above 1, and on placement tables
    drift_from_entry was named on 2 of 30 draws, STRIPES_SEED 11-39 and CI's 2169175137 (gain 1.41 [1.10, 1.85]
    against 9.59 [5.01, 15.66] from the entry; seed 35: 1.89 [1.35, 2.42] against 16.8 [12.3, 20.0];
    docs/bench/session36.md). Since the kernel averages a recording over its own frames (session 39) it is named on
    3 of 13 (1001-1010 and the three seeds that had named it), each wholly below the entry's; before, 4 of 13, one
    (4032634601) overlapping it (docs/bench/session39.md). Since a change of form taken in one step with others must
    gain beside them (session 100), of ten draws (2169175137, 4032634601, 35, 1001-1003, 2369029544 and three fresh)
    it is named on the placement table of 35 only, 1.53 [1.08, 2.01] beside the overlap and drift against 5.95 [3.34,
    9.60] on the entry table; before, also on 2369029544, 2169175137 and 4032634601, each taken with the overlap and
    drift in one step (docs/bench/session100.md)."""
    placement, about, _, _ = drift_reports("placement")
    entry, entry_about, _, _ = drift_reports("entry")
    from_entry = gain_interval(entry, "drift_from_entry")
    assert from_entry is not None, entry_about
    from_placement = gain_interval(placement, "drift_from_entry")
    if from_placement is not None:
        assert from_placement[1] < from_entry[0], (
            f"{about}\nentry gain {from_entry}, placement {from_placement}"
        )


# -- a second camera, end to end ---------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.sampled
@pytest.mark.parametrize(
    ("frames", "style"),
    [
        pytest.param(
            "lit",
            "exposure_us",
            marks=pytest.mark.xfail(
                strict=False,
                reason="open (issue 12): on some draws the fit rows fit a wrong camera (seed 16: a 0.3 us row time, "
                "the truth 49 us) and held-out rows lie where no fit row is (seen: 145 and 139 rows held-out, "
                "STRIPES_SEED=16 and 19; of seeds 11-30, 5 of 40 cases fail, 8 before session 11, 13 before "
                "session 9: docs/bench/second_camera_stripes.md; all on the point-sampled simulator before session "
                "43). On the exact-pulse simulator: 197676555, 531200696 and 3808238891 at 296, 215 and 116 rows, of "
                "40 cases (docs/bench/session44.md; 4111198912 at 341 rows until session 44); of session 48's 42 "
                "drawn cases at session 57, 197676555 and 3808238891 at 296 and 116 rows (531200696 at 9.43 since "
                "session 52; docs/bench/session57/sweep_compare_42.txt)",
            ),
        ),
        pytest.param(
            "interior",
            "exposure",
            marks=pytest.mark.xfail(
                strict=False,
                reason="open (issue 12): the threshold's gain interval can span 1 on the fit rows (seed 26: "
                "0.96-1.45, 106 rows held-out) or a negative integration offset stands in for it (seed 30: 113 rows; "
                "both on the point-sampled simulator before session 43). On the exact-pulse simulator: 1222484455 "
                "and 1211740460 at 34 and 138 rows, of 40 cases; 2083087881 (14 or 94 rows) has an offset whose gain "
                "interval ends at 1.001 +- 0.004 over generator streams (docs/bench/session44.md). Of session 48's "
                "42 drawn cases at session 57, 3503845322 at 187 rows (1222484455 and 1211740460 at 3.26 and 17.04: "
                "docs/bench/session57/sweep_compare_42.txt)",
            ),
        ),
    ],
)
def test_second_camera_heldout_rows_and_parameters(tmp_path, frames, style):
    camera, report = calibrate_drawn_camera(tmp_path, SEED, frames, style, calibration_seed=SEED % 1000)
    about = f"{camera_summary(camera)}\n{json.dumps(report['extended'], default=str)[:1500]}"
    extended, base = report["extended"]["heldout_rmse"], report["base"]["heldout_rmse"]
    # the bar for a second camera is 30 rows held-out
    assert extended <= 30.0, about
    assert extended <= base / 4, about
    assert "exposure_overlap" in report["extended"]["effects"], about
    params = report["extended"]["params"]
    # while the threshold is below pulse and exposure, a stripe spans on + exposure + offset + 2 spread row times
    # - 2 threshold: offset, blooming and threshold trade off, their sum is what the data fix; to 25 us (the
    # driver's rise time is a few us)
    threshold = camera["threshold_grey"] / camera["gain"]
    extra_width = camera["offset"] + 2 * camera["spread"] * camera["row_time"] - 2 * threshold
    fitted_width = params.get("integration_offset_s", 0.0) - 2 * params.get("threshold_s", 0.0)
    if abs(fitted_width - extra_width) > 25e-6:
        # open (reported, not hidden): identification can leave integration_offset out of the written model
        # while the held-out error stays within the bar (seen with STRIPES_SEED=3243074425)
        pytest.xfail(f"stripe width term {fitted_width:.3g} s vs {extra_width:.3g} s\n{about}")
    if frames == "interior":
        # whole stripes of a known width: the row time is identified
        assert params["row_time_s"] == pytest.approx(camera["row_time"], rel=0.1), about
    assert report["extended"]["derived"]["unit_source_exposure"] == (
        "column exposure_us" if style == "exposure_us" else "--exposure-unit-s"
    )


@pytest.mark.slow
@pytest.mark.sampled
def test_an_overlap_of_no_use_alone_is_named_with_the_threshold_it_hosts(tmp_path):
    """A drawn camera (seed 13, whole stripes only) whose exposure overlap alone barely beats a fixed band: it was
    left out for that, with the threshold and offset that live in it (254 rows held-out); judged with them it is
    named, and the written model predicts the held-out rows."""
    _, report = calibrate_drawn_camera(tmp_path, 13, "interior", "exposure", calibration_seed=13)
    overlap = next(r for r in report["identification"] if r["effect"] == "exposure_overlap")
    assert overlap["identified"], overlap["reasons"]
    assert set(overlap["judged_with"]) == {"detection_threshold", "integration_offset"}
    evidence = next(f["evidence"] for f in report["findings"] if f["effect"] == "exposure_overlap")
    assert "with the effects it hosts (detection_threshold, integration_offset)" in evidence
    assert report["extended"]["heldout_rmse"] <= 30.0


@pytest.mark.slow
@pytest.mark.sampled
def test_a_threshold_the_fit_rows_cannot_tell_from_a_negative_offset_is_taken_as_the_threshold(tmp_path):
    """A drawn camera (seed 1804228398, lit frames) whose fit rows hold no pulse or window shorter than its
    threshold: the threshold and a negative integration offset score the same to 1e-12, and which one won was
    rounding (at 02c74c0 the offset, 116 rows held-out: a window longer than the laser period then lights every
    row). The tie is recorded and the threshold, which every table's detection rule implies, is taken."""
    # the table of the simulator the case was found on: the tie is the table's, the rule under test the package's
    _, report = calibrate_drawn_camera(
        tmp_path, 1804228398, "lit", "exposure_us", calibration_seed=398, pulses="sampled"
    )
    steps = report["selection"]["steps"]
    assert steps[0]["tied"] == ["exposure_overlap+integration_offset"], steps[0]
    tried = steps[0]["tried"]
    assert tried["exposure_overlap+integration_offset"] == pytest.approx(
        tried["exposure_overlap+detection_threshold"], rel=1e-6
    )
    assert set(report["extended"]["effects"]) == {"exposure_overlap", "detection_threshold"}
    assert report["extended"]["heldout_rmse"] <= 30.0


@pytest.mark.slow
@pytest.mark.sampled
def test_an_offset_taken_with_the_threshold_is_judged_with_the_noise_the_pair_made_possible(tmp_path):
    """A drawn camera (seed 4111198912, lit frames): selection takes the threshold and an integration offset as one
    step (ratio 1.22, its interval spanning 1), then read noise on the threshold (to 4.09 rows from 8.03); without
    the offset, threshold and noise score 8.23, the noise pinned at 0. Judged only to the pair's step the offset
    was withdrawn, and the model left (the overlap alone) lit every row of a held-out row whose window is longer than
    the laser period: 341 rows held-out. The pair is judged together, with what it hosts."""
    # bootstrap=10: the suite's budget (the withdrawal is rule 2's, whose ratio draws do not follow the flag);
    # the table of the simulator the case was found on (on the exact-pulse table selection takes other steps)
    _, report = calibrate_drawn_camera(
        tmp_path, 4111198912, "lit", "exposure_us", calibration_seed=912, bootstrap=10, pulses="sampled"
    )
    assert report["selection"]["withdrawn"] == []
    results = {r["effect"]: r for r in report["identification"]}
    assert results["integration_offset"]["compared_steps"] == results["detection_threshold"]["compared_steps"]
    assert results["integration_offset"]["identified"], results["integration_offset"]["reasons"]
    assert set(report["extended"]["effects"]) == {
        "exposure_overlap",
        "integration_offset",
        "detection_threshold",
        "detection_noise",
    }
    assert report["extended"]["heldout_rmse"] <= 30.0


@pytest.mark.slow
@pytest.mark.sampled
def test_an_offset_whose_gain_interval_ends_near_1_is_judged_on_the_data_not_the_generator_stream(tmp_path):
    """The same drawn camera on the exact-pulse table: selection takes the threshold, then read noise and an
    integration offset as a pair (7.27 -> 4.59 rows). The offset's ratio, 1.583, has its 5% end at 1.026; with 200
    draws that end moved by +-0.033 between generator streams and fell to 0.987 on the tool's own, which withdrew the
    offset and left the overlap alone: 341 rows held-out (docs/bench/session44.md)."""
    _, report = calibrate_drawn_camera(tmp_path, 4111198912, "lit", "exposure_us", calibration_seed=912)
    results = {r["effect"]: r for r in report["identification"]}
    ratio = results["integration_offset"]["validation_ratio"]
    assert 1.0 < ratio["low"] < 1.1 and ratio["draws"] >= 10_000, ratio
    assert report["selection"]["withdrawn"] == []
    assert report["extended"]["heldout_rmse"] <= 30.0


def fixed_band_table(path, rng: np.random.Generator, camera: dict):
    """A null stripe table on ``camera``'s settings: the paper's band (H/3 rows whatever the settings) plus frame
    noise of 2 rows."""
    lines = ["frequency,exposure_us,duty_cycle,affected_rows_mean"]
    for f in camera["frequencies"]:
        for d in DUTIES:
            for e in camera["exposures_us"][::2]:
                lines.append(f"{f:g}Hz,{e:g},{d},{camera['height'] / 3 + rng.normal(0, 2.0):.3f}")
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.slow
@pytest.mark.sampled
def test_fixed_band_keeps_the_base(tmp_path):
    """Null case: rows follow the paper's band (H/3 whatever the settings, plus frame noise)."""
    rng = np.random.default_rng([SEED, 3])
    camera = draw_camera(rng, "lit")
    table = fixed_band_table(tmp_path / "band.csv", rng, camera)
    report = calibrate_stripes(tmp_path, table, camera["height"])
    assert report["extended"]["effects"] == [], camera_summary(camera)
    assert report["base"]["params"]["band_rows"] == pytest.approx(camera["height"] / 3, abs=2.0)
    assert not report["unexplained_structure"]["structure_remains"], report["unexplained_structure"][
        "summary"
    ]


# -- structure left in the residual ------------------------------------------------------------------------------
FRAME_RATE_HZ = 30.0


def band_table(path, rng: np.random.Generator, height: int, *, flicker: float) -> None:
    """The paper's fixed band (H/3 rows, frame noise of 2 rows) on a grid of settings; ``flicker`` > 0 adds an
    effect no library term has: the band height beats with the laser frequency against the frame rate,
    ``1 + flicker cos(2 pi f / frame rate)`` (a camera whose exposure control locks to the frame clock)."""
    lines = ["frequency,exposure_us,duty_cycle,affected_rows_mean"]
    for f in np.round(np.geomspace(20.0, 2000.0, 9), 1):
        beat = 1.0 + flicker * np.cos(2 * np.pi * f / FRAME_RATE_HZ)
        for d in DUTIES:
            for e in (50, 400, 2000):
                lines.append(f"{f:g}Hz,{e},{d},{height / 3 * beat + rng.normal(0.0, 2.0):.3f}")
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("flicker", [0.0, 0.4], ids=["null", "frame-rate beat"])
def test_residual_structure_of_a_stripe_table(tmp_path, flicker):
    """The residual of the true base model is tested against the table's settings: a beat with the frame rate
    is found (on frequency, where it lives), frame noise alone is not."""
    rng = np.random.default_rng([SEED, 4])
    band_table(tmp_path / "t.csv", rng, 600, flicker=flicker)
    problem = StripeProblem(tmp_path / "t.csv", image_height=600, exposure_unit_s=None)
    truth = Fit(frozenset(), {"band_rows": 200.0})
    items = np.arange(problem.n_items)
    sample = problem.residual_sample(truth, items, rng)
    assert set(sample.covariates) == {"frequency_hz", "exposure_s", "duty", "on_time_s", "predicted_rows"}
    assert [len(r) for r in sample.residual] == [1] * problem.n_items
    mse = float(np.mean(problem.residual(truth, items) ** 2))
    structure = residual_structure(problem, truth, items, base_mse=mse, rng=rng)
    found = {t["variable"] for t in structure["tests"] if t["significant"]}
    if flicker:
        assert structure["structure_remains"] and "frequency_hz" in found, structure["summary"]
    else:
        assert not structure["structure_remains"], structure["summary"]
    with_row_time = Fit(frozenset({"exposure_overlap"}), {"row_time_s": 1 / (30.0 * 600)}, {"frames": "lit"})
    phase = problem.residual_sample(with_row_time, items, rng).covariates["readout_aliasing_phase"]
    assert all(0.0 <= p[0] < 1.0 for p in phase)


@pytest.mark.slow
@pytest.mark.sampled
def test_an_unnamed_stripe_effect_is_reported_as_structure_not_as_a_cause(tmp_path):
    rng = np.random.default_rng([SEED, 5])
    band_table(tmp_path / "beat.csv", rng, 600, flicker=0.4)
    report = calibrate_stripes(tmp_path, tmp_path / "beat.csv", 600)
    about = (
        f"STRIPES_SEED={SEED} {report['unexplained_structure']['summary']} {report['extended']['effects']}"
    )
    assert report["extended"]["effects"] == [], about
    assert report["findings"] == [], about
    assert report["unexplained_structure"]["structure_remains"], about


# -- units and geometry ------------------------------------------------------------------------------------------
def small_table(path, header="frequency,exposure,duty_cycle,camera,affected_rows_mean", cell="Exposure {}"):
    lines = [header] + [
        f"100Hz,{cell.format(e)},{d},Cam,{10 + d + e / 10:.1f}" for e in (5, 20) for d in (5, 30)
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_missing_units_and_height_name_their_flags(tmp_path):
    table = small_table(tmp_path / "t.csv")
    with pytest.raises(ValueError, match=r"--exposure-unit-s .*1e-4.*exposure_us"):
        read_stripe_table(table, image_height=720, exposure_unit_s=None)
    with pytest.raises(ValueError, match=r"--image-height"):
        read_stripe_table(table, image_height=None, exposure_unit_s=1e-4)
    with pytest.raises(ValueError, match=r"--exposure-unit-s"):
        calibrate(CalibrateConfig(attack="laser_color_strip", measured=str(table), out=str(tmp_path / "o")))
    _, meta = read_stripe_table(table, image_height=720, exposure_unit_s=1e-4)
    assert meta["exposure_s"].tolist() == pytest.approx([5e-4] * 2 + [2e-3] * 2)
    assert meta["sources"]["exposure"] == "--exposure-unit-s"


def test_units_and_height_read_from_the_table(tmp_path):
    table = small_table(
        tmp_path / "us.csv", "frequency,exposure_us,duty_cycle,camera,affected_rows_mean", "{}"
    )
    _, meta = read_stripe_table(table, image_height=480, exposure_unit_s=None)
    assert meta["exposure_s"].max() == pytest.approx(20e-6)
    with pytest.raises(ValueError, match="contradicts"):
        read_stripe_table(table, image_height=480, exposure_unit_s=1e-4)
    suffixed = small_table(tmp_path / "suffix.csv", cell="{} us")
    _, meta = read_stripe_table(suffixed, image_height=480, exposure_unit_s=None)
    assert meta["exposure_s"].min() == pytest.approx(5e-6)
    text = table.read_text().splitlines()
    (tmp_path / "h.csv").write_text(
        "\n".join([text[0] + ",image_height"] + [line + ",600" for line in text[1:]]) + "\n"
    )
    _, meta = read_stripe_table(tmp_path / "h.csv", image_height=None, exposure_unit_s=None)
    assert meta["image_height"] == 600 and meta["sources"]["image_height"] == "column image_height"
    with pytest.raises(ValueError, match="contradicts column image_height"):
        read_stripe_table(tmp_path / "h.csv", image_height=720, exposure_unit_s=None)


def test_each_rows_recording_length_is_read_and_predicts_its_drifting_videos(tmp_path):
    """A ``recording_frames`` column gives the frames of each row's video: a drifting recording is predicted at
    them (the kernel at N frames, not the long limit, which it differs from here); the source is reported; a count
    that is not a whole number >= 1 is refused, naming the column."""
    header = "frequency,exposure_us,duty_cycle,camera,affected_rows_mean"
    plain = small_table(tmp_path / "plain.csv", header, "{}")
    text = plain.read_text().splitlines()
    lengths = (6, 6, 12, 12)
    framed = tmp_path / "framed.csv"
    rows = [f"{line},{n}" for line, n in zip(text[1:], lengths, strict=True)]
    framed.write_text("\n".join([text[0] + ",recording_frames", *rows]) + "\n")
    effects = frozenset({"exposure_overlap", "phase_drift"})
    problems = {
        name: StripeProblem(table, image_height=480, exposure_unit_s=None, frames="interior")
        for name, table in (("plain", plain), ("framed", framed))
    }
    assert problems["framed"].sources["recording_frames"] == "column recording_frames"
    assert "no recording_frames column" in problems["plain"].sources["recording_frames"]
    # 100 Hz at 20 us rows: a period of 500 rows, one stripe per 480-row frame; both recordings drift 0.6
    params = {"row_time_s": 2e-5} | {name: 0.6 for name in problems["framed"].drift_names}
    items = np.arange(4)
    framed_rows = problems["framed"].predict(effects, params, items, frames="interior")
    expected = physics.rolling_shutter_rows_lit(
        torch.as_tensor(problems["framed"].frequency_hz),
        torch.as_tensor(problems["framed"].duty),
        torch.as_tensor(problems["framed"].exposure_s),
        2e-5,
        image_rows=480,
        frames="interior",
        drift=torch.full((4,), 0.6, dtype=torch.float64),
        recording_frames=torch.tensor(lengths),
    )
    torch.testing.assert_close(framed_rows, expected, rtol=1e-12, atol=1e-12)
    long_rows = problems["plain"].predict(effects, params, items, frames="interior")
    assert float((framed_rows - long_rows).abs().max()) > 0.5, (framed_rows, long_rows)
    for bad in ("0", "2.5", "many"):
        broken = tmp_path / f"bad_{bad}.csv"
        broken.write_text(framed.read_text().replace(",12\n", f",{bad}\n", 1))
        with pytest.raises(ValueError, match="recording_frames must hold whole frame counts >= 1"):
            read_stripe_table(broken, image_height=480, exposure_unit_s=None)


def test_a_table_of_two_cameras_is_refused(tmp_path):
    table = small_table(tmp_path / "t.csv")
    lines = table.read_text().splitlines()
    lines[-1] = lines[-1].replace(",Cam,", ",OtherCam,")
    table.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match="mixes cameras"):
        read_stripe_table(table, image_height=720, exposure_unit_s=1e-4)
    with pytest.raises(ValueError, match="valid: auto, all, lit, interior"):
        calibrate(
            CalibrateConfig(
                attack="laser_color_strip",
                measured=str(small_table(tmp_path / "u.csv")),
                out=str(tmp_path / "o"),
                image_height=720,
                exposure_unit_s=1e-4,
                stripe_frames="most",
            )
        )


def two_sweeps_table(path, b_confidence: float) -> dict[str, float]:
    """Two duty sweeps at 25 Hz from the kernel itself (a 720-row camera, 20 us rows, 100 us extra integration):
    exposure 50 drifts 0.3 of a period from the entry, and its wide stripes are cut; exposure 200 is locked, but
    its widest video reads 30 rows short with a 95% half-width of ``b_confidence`` rows (the rest 1 row)."""
    sweeps = {50: (0.3, (1, 5, 10, 20, 25, 30)), 200: (0.0, (1, 5, 10, 15, 20))}
    lines = ["frequency,exposure_us,duty_cycle,affected_rows_mean,affected_rows_95ci"]
    for exposure, (drift, duties) in sweeps.items():
        rows = physics.rolling_shutter_rows_lit(
            torch.full((len(duties),), 25.0),
            torch.tensor(duties, dtype=torch.float64) / 100.0,
            torch.full((len(duties),), exposure * 1e-6),
            20e-6,
            image_rows=720,
            integration_offset_s=100e-6,
            frames="interior",
            drift=torch.full((len(duties),), drift),
            drift_start="entry",
        ).tolist()
        for duty, mean in zip(duties, rows, strict=True):
            short, confidence = (30.0, b_confidence) if (exposure, duty) == (200, 20) else (0.0, 1.0)
            lines.append(f"25Hz,{exposure},{duty},{mean - short:.3f},{confidence}")
    path.write_text("\n".join(lines) + "\n")
    return {"cut": sweeps[50][0]}


@pytest.mark.parametrize("b_confidence", [60.0, 1.0], ids=["within its error", "beyond its error"])
def test_a_drift_that_one_video_within_its_error_calls_for_is_locked(tmp_path, b_confidence):
    """A recording's drift is kept only when its own fit rows call for it beyond their measurement error: one video
    30 rows short with a 95% half-width of 60 rows leaves its sweep locked (a drift there would cut the sweep's
    wider videos, which this table does not hold); the same shortfall measured within 1 row keeps the drift, and a
    drift that cuts none of its recording's stripes is locked either way. The truly drifting sweep keeps its drift.

    The fit starts from the camera's own locked values: from the locked model's fit the drift search does not find
    the exposure-200 sweep's drift at all (its grid starts from a row time 25% off), which would leave the rule
    untested."""
    table = tmp_path / "sweeps.csv"
    truth = two_sweeps_table(table, b_confidence)
    problem = StripeProblem(table, image_height=720, exposure_unit_s=None)
    assert problem.sources["standard_error"] == "column affected_rows_95ci / 1.96"
    assert problem.standard_error[0] == pytest.approx(1.0 / 1.959964)
    effects = frozenset({"exposure_overlap", "integration_offset", "phase_drift", "drift_from_entry"})
    items = np.arange(problem.n_items)
    camera = {"row_time_s": 20e-6, "integration_offset_s": 100e-6}
    flat = problem.drifts_without_evidence(
        effects, camera | {"drift_25Hz_exposure50": 0.3, "drift_25Hz_exposure200": 0.05}, items
    )
    assert flat == ["drift_25Hz_exposure200"], flat
    start = Fit(effects - set(DRIFT_EFFECTS), camera, {"frames": "interior"})
    fit = problem.fit(effects, items, start)
    drifts = {name: round(fit.params[name], 3) for name in problem.drift_names}
    locked = fit.extra["drifts_locked_for_want_of_evidence"]
    about = f"drifts {drifts}, locked for want of evidence {locked}"
    assert drifts["drift_25Hz_exposure50"] == pytest.approx(truth["cut"], abs=0.03), about
    if b_confidence > 30.0:
        assert locked == ["drift_25Hz_exposure200"] and drifts["drift_25Hz_exposure200"] == 0.0, about
    else:
        assert locked == [] and drifts["drift_25Hz_exposure200"] > 0.1, about


def test_confidence_half_widths_must_be_non_negative(tmp_path):
    table = tmp_path / "sweeps.csv"
    two_sweeps_table(table, -1.0)
    with pytest.raises(ValueError, match="confidence half-widths must be finite and non-negative"):
        read_stripe_table(table, image_height=720, exposure_unit_s=None)
