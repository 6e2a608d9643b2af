"""Acceptance on the measured third-party data in ../shared/measured (read by path; skipped when absent).

Every threshold is a stated rule, not a copy of the last measured value:
- projection: the issue's acceptance limit for held-out projection data (26 grey levels), and a gain whose
  paired item-bootstrap interval lies above 1 (the extension is better on held-out rows, not by chance);
- stripes (C-stripes' rule): predict each mean within one frame's spread of the counts (the table's median
  affected_rows_std);
- laser captures: the written model must beat the Gaussian spot (ratio interval above 1), and every named cause
  must have passed identification (no own parameter at a bound).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from lerobot_phantom.calibration.cli import CalibrateConfig, build_problem, calibrate
from lerobot_phantom.calibration.core import seeded_split
from lerobot_phantom.transforms.registry import make_attack

MEASURED = Path(__file__).parents[2].parent / "shared" / "measured"
PROJECTION_LIMIT = 26.0  # grey levels: issue 12's acceptance limit for held-out projection data

pytestmark = [
    pytest.mark.shared,
    pytest.mark.skipif(not MEASURED.is_dir(), reason=f"measured data not found at {MEASURED}"),
]


def run(tmp_path, attack, relative, **options):
    return calibrate(
        CalibrateConfig(
            attack=attack, measured=str(MEASURED / relative), out=str(tmp_path / "out"), **options
        )
    )


def assert_named_causes_are_identified(report):
    named = {f["effect"] for f in report["findings"]} - {"shot_noise"}
    # a cause an identified form implies (the shoulder's gamma encoding) is named without a term of its own
    implied = {r["effect"] for r in report["identification"] if r.get("implied_by")}
    assert named - implied == set(report["extended"]["effects"]) - {"shot_noise"}
    for result in report["identification"]:
        assert result["identified"] == (result["effect"] in named), result
        if result["identified"]:
            for name, value in result["params"].items():
                low, high = (result["intervals"][name]["low"], result["intervals"][name]["high"])
                assert low <= value <= high
                assert not result["reasons"]


@pytest.mark.slow
@pytest.mark.sampled
def test_logitech_stripes(tmp_path):
    table = MEASURED / "rolling_shutter/logitech_stripe_rows.csv"
    # the table's README: exposure in UVC units of 100 us, 720-row frames (the table itself states neither)
    report = calibrate(
        CalibrateConfig(
            attack="laser_color_strip",
            measured=str(table),
            out=str(tmp_path / "out"),
            image_height=720,
            exposure_unit_s=1e-4,
        )
    )
    assert 80 <= report["base"]["heldout_rmse"] <= 140  # the paper's fixed band
    # rule: predict each mean within one frame's spread of the counts (the table's median affected_rows_std)
    frame_spread = float(np.median(pd.read_csv(table)["affected_rows_std"]))
    assert report["extended"]["heldout_rmse"] <= frame_spread
    assert "exposure_overlap" in report["extended"]["effects"]
    attack = make_attack("laser_color_strip", intensity=1.0, calibration=str(tmp_path / "out"))
    assert attack.model == "rolling_shutter"
    assert attack.rolling_shutter["row_time_s"] == pytest.approx(report["extended"]["params"]["row_time_s"])


@pytest.mark.slow
@pytest.mark.sampled
@pytest.mark.parametrize("name", ["stop_sign", "bottle"])
def test_slap_triples(tmp_path, name):
    relative = f"projection/slap_{name}_triples.csv"
    report = run(tmp_path, "light_projection", relative)
    assert report["extended"]["effects"], "the paper's alpha blend is not what the camera recorded"
    assert report["extended"]["heldout_rmse"] <= PROJECTION_LIMIT
    assert report["gain"]["rmse_ratio_interval"]["low"] > 1.0
    assert_named_causes_are_identified(report)
    # SLAP's addition_r,g,b is the colour the projector emitted: its light is the projector's transfer of it
    assert report["input"]["recording"]["pattern_record"].startswith("emitted")
    assert "projector_gamma" in report["extended"]["params"]
    # the attack calibrated.json builds is the written model: its light on the held-out rows (the CLI's split)
    # scores the report's held-out RMSE (until session 87 the stop sign's shoulder reached it as a power law: 13.38
    # against 9.83 grey levels, docs/bench/session87/transform_tone_gain_21404e0.txt)
    attack = make_attack("light_projection", intensity=1.0, calibration=str(tmp_path / "out"))
    cfg = CalibrateConfig(attack="light_projection", measured=str(MEASURED / relative))
    problem = build_problem(cfg)
    _, heldout = seeded_split(problem.n_items, cfg.heldout, cfg.seed)
    rows = torch.as_tensor(heldout)
    surface, projected = (t[rows].T.reshape(1, 3, -1, 1) for t in (problem.surface, problem.projected))
    light = attack.project(surface, projected, torch.ones(1, dtype=torch.float64)).reshape(3, -1).T
    rmse = 255 * float((light - problem.captured[rows]).pow(2).mean().sqrt())
    assert rmse == pytest.approx(report["extended"]["heldout_rmse"], rel=1e-6)


@pytest.mark.slow
@pytest.mark.sampled
def test_laser_capture_beats_gaussian_spot(tmp_path):
    # all four captures: effects are shared, so one capture's halo exponent at its bound keeps halo unnamed
    report = run(tmp_path, "laser_blinding", "blinding")
    assert report["gain"]["rmse_ratio_interval"]["low"] > 1.0
    assert_named_causes_are_identified(report)
    if "linear_light_saturation" in report["extended"]["effects"]:
        assert all(c["saturation_radius_px"] > 0 for c in report["extended"]["derived"]["captures"])
