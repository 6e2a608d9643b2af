"""camsim draws calibrated as a user calibrates them, for this session's attack benches: each ``CASE:CASE_SEED`` is
rendered by tests/calibration/test_independent_sim.py, split as the CLI splits it and calibrated by
``lerobot-phantom-calibrate`` (its own selection), and handed out while its folder exists (the pairs in
``folder / "pairs"``, camsim's file names; the calibration in ``folder / "out"``)."""

from __future__ import annotations

import json
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch


@dataclass
class CalibratedDraw:
    name: str
    seed: int
    folder: Path
    problem: object
    fit_items: np.ndarray
    heldout: np.ndarray
    report: dict
    kwargs: dict  # calibrated.json's attack options

    @property
    def out(self) -> Path:
        return self.folder / "out"

    def fit(self):
        """The report's extended fit, fitted again on the fit items (deterministic)."""
        return self.problem.fit(frozenset(self.report["extended"]["effects"]), self.fit_items)


def calibrated_draws(attack: str, draws: list[str]) -> Iterator[CalibratedDraw]:
    import test_independent_sim as sim

    from lerobot_phantom.calibration.cli import CalibrateConfig, calibrate

    torch.set_num_threads(1)
    for draw in draws:
        name, seed = draw.split(":")
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            problem, fit_items, heldout = sim.drawn_split(name, int(seed), folder / "pairs")
            config = CalibrateConfig(
                attack=attack, measured=str(folder / "pairs"), out=str(folder / "out"), seed=int(seed) % 2**31
            )
            report = calibrate(config)
            kwargs = json.loads((folder / "out" / "calibrated.json").read_text())["kwargs"]
            yield CalibratedDraw(name, int(seed), folder, problem, fit_items, heldout, report, kwargs)
