"""Held-out items never inform a fit: altering them changes no fitted parameter, interval or selected effect."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import calibration_testkit as kit

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate
from lerobot_phantom.calibration.core import seeded_split

MEASURED = Path(__file__).parents[2].parent / "shared" / "measured"


def fitted_part(report: dict) -> dict:
    """Everything in report.json that must depend on the fit items only."""
    return {
        "base": (report["base"]["params"], report["base"]["param_intervals"]),
        "extended": (report["extended"]["effects"], report["extended"]["params"]),
        "intervals": report["extended"]["param_intervals"],
        "selection": (report["selection"]["selected"], report["selection"]["steps"]),
        "identification": report["identification"],
        # the noise model is fitted and judged on the fit items too; only its held-out scores may move
        "noise": {
            k: v
            for k, v in report.get("noise", {}).items()
            if k not in ("heldout_noise_scale_ratio", "residual_vs_signal")
        },
    }


def scores(report: dict) -> tuple[float, float]:
    return report["base"]["heldout_rmse"], report["extended"]["heldout_rmse"]


def test_altering_heldout_frames_changes_scores_but_no_fit(tmp_path):
    measured = tmp_path / "measured"
    measured.mkdir()
    kit.render_em_truncation(measured, {"free_band_position"}, seed=51)
    seed = 5

    def run(folder, name):
        return calibrate(
            CalibrateConfig(
                attack="em_truncation", measured=str(folder), out=str(tmp_path / f"out_{name}"), seed=seed
            )
        )

    original = run(measured, "original")
    altered = tmp_path / "altered"
    shutil.copytree(measured, altered)
    table = pd.read_csv(altered / "pairs.csv")
    _, heldout = seeded_split(len(table), 0.2, seed)
    rng = np.random.default_rng(0)
    for i in heldout:
        path = altered / table["attacked"][i]
        shape = np.asarray(Image.open(path)).shape
        Image.fromarray(rng.integers(0, 256, shape, dtype=np.uint8)).save(path)
    changed = run(altered, "altered")
    assert fitted_part(changed) == fitted_part(original)
    assert scores(changed) != scores(original)  # the alteration did reach the held-out scores


@pytest.mark.shared
@pytest.mark.slow
@pytest.mark.skipif(not MEASURED.is_dir(), reason=f"measured data not found at {MEASURED}")
def test_altering_heldout_table_rows_of_the_shared_triples_changes_no_fit(tmp_path):
    source = MEASURED / "projection" / "slap_stop_sign_triples.csv"
    table = pd.read_csv(source)
    seed = 0
    _, heldout = seeded_split(len(table), 0.2, seed)
    rng = np.random.default_rng(1)
    altered = table.copy()
    columns = [f"outcome_{c}" for c in "rgb"]
    altered.loc[heldout, columns] = rng.integers(0, 256, (len(heldout), 3))
    altered_path = tmp_path / "altered.csv"
    altered.to_csv(altered_path, index=False)

    def run(path, name):
        return calibrate(
            CalibrateConfig(
                attack="light_projection", measured=str(path), out=str(tmp_path / f"out_{name}"), seed=seed
            )
        )

    original, changed = run(source, "original"), run(altered_path, "altered")
    assert fitted_part(changed) == fitted_part(original)
    assert scores(changed) != scores(original)
