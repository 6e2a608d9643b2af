"""``lerobot-phantom-calibrate``: fit an attack simulation to measured data, name what it gets wrong, extend it.

    lerobot-phantom-calibrate --attack laser_color_strip --measured ../shared/measured/rolling_shutter/logitech_stripe_rows.csv --image-height 720 --exposure-unit-s 1e-4 --out outputs/cal/stripes
    lerobot-phantom-calibrate --attack light_projection --measured slap_stop_sign_triples.csv --out outputs/cal/stop
    lerobot-phantom-calibrate --attack laser_blinding --measured ../shared/measured/blinding --out outputs/cal/laser
    lerobot-phantom-calibrate --attack ultrasound_blur --measured my_captures/ --out outputs/cal/blur   # pairs.csv

Inputs (recognised from the path and the table columns):
  stripe tables (frequency, exposure, duty_cycle, affected_rows_mean)   -> laser_color_strip
  colour-triple tables (origin_*, addition_*, outcome_*)                -> light_projection
  laser captures without scene (image file or folder of images)         -> laser_blinding
  frame pairs (folder with pairs.csv: clean,attacked[,pattern][,intensity],...) -> laser_blinding,
      light_projection, ultrasound_blur, em_color_strip, em_truncation, laser_color_strip
Light projection's frame pairs say what their pattern is: a pattern_record column (emitted: the frame the projector
was sent; captured: the projection as the camera captured it) or --pattern-record. Laser blinding's pairs may add a
pattern_dark column: the laser capture repeated with the laser off (a dark frame), read for the dark room's shape.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from lerobot_phantom._cli import normalize_argv
from lerobot_phantom.calibration.captures import IMAGE_SUFFIXES, MultiCapture
from lerobot_phantom.calibration.core import Fit, Problem, Step, seeded_split, single_threaded
from lerobot_phantom.calibration.example import write_example
from lerobot_phantom.calibration.frame_models import FRAME_PROBLEMS, FrameProblem, load_pairs
from lerobot_phantom.calibration.identify import parameter_intervals, select_and_identify
from lerobot_phantom.calibration.noise import apply_noise_finding, held_back_for_structure, select_shot_noise
from lerobot_phantom.calibration.projection import TripleProblem, is_triple_table
from lerobot_phantom.calibration.report import build_report, write_outputs
from lerobot_phantom.calibration.stripes import StripeProblem, is_stripe_table
from lerobot_phantom.calibration.structure import fit_items_structure
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS

SUPPORTED = {
    "stripe_table": ("laser_color_strip",),
    "colour_triples": ("light_projection",),
    "laser_captures": ("laser_blinding",),
    "frame_pairs": tuple(FRAME_PROBLEMS),
}


@dataclass
class CalibrateConfig:
    # Attack whose simulation is calibrated (one of the camera attacks).
    attack: str = ""
    # Measured data: a stripe/colour-triple CSV, a laser capture (file or folder), or a folder with pairs.csv.
    measured: str = ""
    # Output directory for report.json, report.md (+ figures) and calibrated.json.
    out: str = ""
    # Seed of the held-out split, the inner folds and the pixel samples.
    seed: int = 0
    # Share of items (table rows, capture tiles, whole image pairs) held out for the final score.
    heldout: float = 0.2
    # Relative validation-RMSE reduction an extension must bring to be kept.
    margin: float = 0.05
    # Inner cross-validation folds for selection.
    folds: int = 4
    # Bootstrap resamples (over fit items) behind every parameter's interval; the gain's interval uses more.
    bootstrap: int = 30
    # Write a synthetic measured-data example into this directory, print how to calibrate it, and stop.
    make_example: str = ""
    # Stripe tables: image rows of the camera's frames (required unless the table has an image_height column).
    image_height: int | None = None
    # Stripe tables: seconds per unit of the exposure values (required unless the table states the unit, e.g. an
    # exposure_us column or values such as "32us"; UVC cameras such as the Logitech table: 1e-4).
    exposure_unit_s: float | None = None
    # Stripe tables: which frames the table's means averaged: all, lit (frames with a lit row), interior (frames
    # whose first and last rows are dark), or auto (the rule that fits the fit split best, reported).
    stripe_frames: str = "auto"
    # Light projection: what the recorded projected image is, emitted (the frame the projector was sent) or captured
    # (the projection as this camera captured it, e.g. on a board in the dark). Required for frame pairs unless
    # pairs.csv has a pattern_record column; colour-triple tables are emitted (SLAP's format).
    pattern_record: str | None = None
    # Frame pairs: frames are resized so their longer side is at most this many pixels.
    max_side: int = 256
    # Laser captures: captures are resized so their longer side is at most this many pixels.
    capture_max_side: int = 128


def detect_input(path: Path) -> str:
    if not path.exists():
        raise FileNotFoundError(f"--measured {path} does not exist")
    if path.is_dir():
        if (path / "pairs.csv").is_file():
            return "frame_pairs"
        if any(p.suffix.lower() in IMAGE_SUFFIXES for p in path.iterdir()):
            return "laser_captures"
        raise ValueError(f"{path}: a folder must hold pairs.csv (frame pairs) or laser capture images")
    if path.suffix.lower() in IMAGE_SUFFIXES:
        return "laser_captures"
    if path.suffix.lower() == ".csv":
        columns = pd.read_csv(path, nrows=0).columns
        if is_stripe_table(columns):
            return "stripe_table"
        if is_triple_table(columns):
            return "colour_triples"
        raise ValueError(
            f"{path}: unknown table; stripe tables need frequency, exposure, duty_cycle, affected_rows_mean and "
            "colour-triple tables origin_r..outcome_b"
        )
    raise ValueError(f"{path}: not a CSV table, an image ({', '.join(IMAGE_SUFFIXES)}) or a folder")


def build_problem(cfg: CalibrateConfig) -> Problem:
    if cfg.attack not in CAMERA_ATTACKS:
        raise ValueError(f"unknown --attack {cfg.attack!r}; valid: {', '.join(CAMERA_ATTACKS)}")
    path = Path(cfg.measured)
    kind = detect_input(path)
    if cfg.attack not in SUPPORTED[kind]:
        raise ValueError(
            f"--measured {path} is {kind.replace('_', ' ')}, which calibrates {', '.join(SUPPORTED[kind])}, "
            f"not {cfg.attack!r}"
        )
    if cfg.pattern_record is not None and cfg.attack != "light_projection":
        raise ValueError(
            f"--pattern-record describes light projection's patterns; drop it for --attack {cfg.attack}"
        )
    if kind == "stripe_table":
        return StripeProblem(
            path, image_height=cfg.image_height, exposure_unit_s=cfg.exposure_unit_s, frames=cfg.stripe_frames
        )
    if kind == "colour_triples":
        return TripleProblem(path, pattern_record=cfg.pattern_record)
    if kind == "laser_captures":
        return MultiCapture(path, max_side=cfg.capture_max_side, seed=cfg.seed)
    options = {"pattern_record": cfg.pattern_record} if cfg.attack == "light_projection" else {}
    return FRAME_PROBLEMS[cfg.attack](load_pairs(path, max_side=cfg.max_side), cfg.seed, **options)


def calibrate(cfg: CalibrateConfig) -> dict:
    """Run the whole calibration, write the outputs into ``cfg.out`` and return the report."""
    if not cfg.out:
        raise ValueError("--out is required (a directory for report.json, report.md and calibrated.json)")
    measured, out = Path(cfg.measured).resolve(), Path(cfg.out).resolve()
    if out == measured or (measured.is_dir() and out.is_relative_to(measured)):
        raise ValueError(
            f"--out {out} lies inside the measured data {measured}; calibration never writes there"
        )
    if not 0.0 <= cfg.margin < 1.0:
        raise ValueError(f"--margin must lie in [0, 1), got {cfg.margin}")
    if cfg.bootstrap < 2:
        raise ValueError(f"--bootstrap must be at least 2 resamples, got {cfg.bootstrap}")
    with single_threaded():
        problem = build_problem(cfg)
        with problem.fits_kept():
            fit_items, heldout_items = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
            # selection, fits and parameter intervals see the fit items only; each stage has its own stream, so
            # nothing about the held-out items can change what is fitted or selected
            steps, chain, selection, withdrawn = select_and_identify(
                problem, fit_items, seed=cfg.seed, margin=cfg.margin, folds=cfg.folds, draws=cfg.bootstrap
            )
            base, extended = chain[0], selection.fit
            base_intervals = parameter_intervals(
                problem, base, fit_items, draws=cfg.bootstrap, rng=np.random.default_rng([cfg.seed, 2])
            )
            report = build_report(
                problem,
                input_path=Path(cfg.measured),
                fit_items=fit_items,
                heldout_items=heldout_items,
                base=base,
                base_intervals=base_intervals,
                selection=selection,
                steps=steps,
                seed=cfg.seed,
                margin=cfg.margin,
                folds=cfg.folds,
                withdrawn=withdrawn,
            )
            if isinstance(problem, FrameProblem):
                # noise changes no prediction, so it is judged by likelihood after the mean model (see noise.py)
                extended = apply_noise_finding(
                    report, extended, judge_noise(problem, cfg, extended, steps, fit_items, heldout_items)
                )
            write_outputs(problem, report, base, extended, heldout_items, out)
    return report


def judge_noise(
    problem: FrameProblem,
    cfg: CalibrateConfig,
    fit: Fit,
    steps: list[Step],
    fit_items: np.ndarray,
    heldout_items: np.ndarray,
) -> dict:
    """noise.py's verdict on ``shot_noise`` under the written mean model ``fit``: its conditions 1-4, then, where
    they name it, condition 5 on the fit pairs' cross-fitted residuals (``steps``: the selection's, whose first
    score is the base model's cross-validated RMSE over the fit pairs, frame pairs being selected by RMSE)."""
    noise = select_shot_noise(
        problem, fit, fit_items, heldout_items, seed=cfg.seed, margin=cfg.margin, folds=cfg.folds
    )
    if not noise["kept"]:
        return noise
    structure = fit_items_structure(
        problem,
        fit,
        fit_items,
        base_mse=steps[0].validation_error ** 2,
        folds=cfg.folds,
        seed=cfg.seed,
        rng=np.random.default_rng([cfg.seed, 5]),
    )
    return held_back_for_structure(noise, structure)


def main(argv: list[str] | None = None) -> None:
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    import draccus

    cfg = draccus.parse(
        CalibrateConfig, args=normalize_argv(sys.argv[1:] if argv is None else list(argv), bare_flags=())
    )
    if cfg.make_example:
        path = write_example(Path(cfg.make_example), seed=cfg.seed)
        print(
            f"wrote {path}; calibrate it with:\n  lerobot-phantom-calibrate --attack light_projection "
            f"--measured {path} --out {Path(cfg.make_example) / 'calibration'}"
        )
        return
    report = calibrate(cfg)
    print(
        f"{report['attack']}: base held-out RMSE {report['base']['heldout_rmse']:.3g} {report['units']}, "
        f"extended {report['extended']['heldout_rmse']:.3g} with {report['extended']['effects'] or 'no extension'} "
        f"(ratio {report['gain']['rmse_ratio']:.2f}) -> {cfg.out}"
    )


if __name__ == "__main__":
    main()
