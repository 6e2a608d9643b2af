"""Loading ``calibrated.json`` (written by ``lerobot-phantom-calibrate``) as constructor options of an attack.

``make_attack(name, calibration=DIR)`` merges ``calibrated_kwargs(name, DIR)`` under any explicit keyword
arguments, so training and evaluation can run the measured physics instead of the paper's formulas.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

CALIBRATED_FILE = "calibrated.json"
SUPPORTED_FORMATS = (1,)


def calibrated_kwargs(name: str, calibration_dir: str | Path) -> dict[str, Any]:
    """Constructor options for attack ``name`` from ``calibration_dir/calibrated.json``."""
    directory = Path(calibration_dir)
    path = directory / CALIBRATED_FILE if directory.is_dir() or directory.suffix != ".json" else directory
    if not path.is_file():
        raise FileNotFoundError(
            f"no {CALIBRATED_FILE} in {directory}; write one with "
            f"`lerobot-phantom-calibrate --attack {name} --measured PATH --out {directory}`"
        )
    try:
        payload = json.loads(path.read_text())
    except json.JSONDecodeError as err:
        raise ValueError(f"{path} is not valid JSON: {err}") from err
    if not isinstance(payload, dict) or not {"attack", "kwargs"} <= set(payload):
        raise ValueError(f"{path} is not a calibration file: it needs 'attack' and 'kwargs'")
    if payload.get("format") not in SUPPORTED_FORMATS:
        raise ValueError(
            f"{path} has format {payload.get('format')!r}; this version reads {SUPPORTED_FORMATS}"
        )
    if payload["attack"] != name:
        raise ValueError(
            f"{path} calibrates {payload['attack']!r}, not {name!r}; use a calibration directory per attack"
        )
    kwargs = payload["kwargs"]
    if not isinstance(kwargs, dict):
        raise ValueError(f"{path}: 'kwargs' must be an object, got {type(kwargs).__name__}")
    return dict(kwargs)
