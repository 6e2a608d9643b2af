"""``lerobot-phantom-calibrate --make-example DIR``: a measured-data example that calibrates without ../shared."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("HF_HUB_OFFLINE", "1")

from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate, main
from lerobot_phantom.calibration.example import EXAMPLE_FILE


@pytest.mark.slow
def test_the_example_is_written_and_its_physics_found(tmp_path, capsys):
    folder = tmp_path / "example"
    main(["--make-example", str(folder)])
    printed = capsys.readouterr().out
    assert f"--measured {folder / EXAMPLE_FILE}" in printed
    with pytest.raises(FileExistsError):
        main(["--make-example", str(folder)])
    report = calibrate(
        CalibrateConfig(
            attack="light_projection", measured=str(folder / EXAMPLE_FILE), out=str(tmp_path / "out")
        )
    )
    # rendered with additive light modulated by the surface's reflectance and a clipping sensor
    assert {"additive_light", "albedo_modulation"} <= set(report["extended"]["effects"])
    assert report["gain"]["rmse_ratio_interval"]["low"] > 1.5
    assert report["extended"]["heldout_rmse"] < 3.0  # 8-bit noise of 1 grey level, quantised
    # groups selection set aside are ones it scored, and report.md gives each one's reason
    steps = report["selection"]["steps"]
    set_aside = [(group, why) for step in steps for group, why in step["set_aside"].items()]
    assert set_aside, "the example's tone_shoulder runs to its bounds: its groups are set aside"
    assert all(set(step["set_aside"]) <= set(step["tried"]) for step in steps)
    markdown = (tmp_path / "out" / "report.md").read_text()
    assert all(f"{group}: " in markdown and f"(not eligible: {why})" in markdown for group, why in set_aside)
