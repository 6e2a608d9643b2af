"""Loading ``calibrated.json`` (written by ``lerobot-phantom-calibrate``) as constructor options of an attack.

``make_attack(name, calibration=DIR)`` merges ``calibrated_kwargs(name, DIR)`` under any explicit keyword
arguments, so training and evaluation can run the measured physics instead of the paper's formulas;
``make_attacks(names, calibration=DIR)`` does so for the attacks ``DIR`` calibrates and keeps the paper's physics for
the others.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

CALIBRATED_FILE = "calibrated.json"
SUPPORTED_FORMATS = (1,)


def calibration_set(calibration_dir: str | Path) -> dict[str, tuple[Path, dict[str, Any]]]:
    """Attack name -> (``calibrated.json``, its checked payload) for every attack ``calibration_dir`` calibrates.

    ``calibration_dir`` is what one ``lerobot-phantom-calibrate --out DIR`` wrote (``DIR/calibrated.json``, one
    attack), that file itself, or a calibration set: one such directory per attack (``DIR/<attack>/calibrated.json``),
    so that training and evaluation that mix several attacks can run the measured physics of each.
    """
    directory = Path(calibration_dir)
    if directory.is_file() or directory.suffix == ".json":
        candidates = [directory]
    elif (directory / CALIBRATED_FILE).is_file():
        candidates = [directory / CALIBRATED_FILE]
    else:
        candidates = sorted(directory.glob(f"*/{CALIBRATED_FILE}"))
    if not candidates:
        raise FileNotFoundError(
            f"no {CALIBRATED_FILE} in {directory} or its subdirectories; write one per attack with "
            f"`lerobot-phantom-calibrate --attack NAME --measured PATH --out {directory}/NAME`"
        )
    found: dict[str, tuple[Path, dict[str, Any]]] = {}
    for path in candidates:
        payload = read_calibration(path)
        attack = payload["attack"]
        if attack in found:
            raise ValueError(f"{found[attack][0]} and {path} both calibrate {attack!r}; keep one")
        if path.parent != directory and path.parent.name != attack:
            raise ValueError(f"{path} calibrates {attack!r}: move it to {directory / attack}")
        found[attack] = (path, payload)
    return found


def read_calibration(path: Path) -> dict[str, Any]:
    """The checked payload of one ``calibrated.json``."""
    if not path.is_file():
        raise FileNotFoundError(f"{path} does not exist; write it with `lerobot-phantom-calibrate`")
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
    if not isinstance(payload["kwargs"], dict):
        raise ValueError(f"{path}: 'kwargs' must be an object, got {type(payload['kwargs']).__name__}")
    return payload


def calibrated_options(names: Any, calibration_dir: str | Path | None) -> dict[str, dict[str, Any]]:
    """Constructor options of each of ``names`` that ``calibration_dir`` calibrates, read once (``{}`` without a
    directory); the directory must calibrate at least one of ``names``, and the error names what it holds."""
    if calibration_dir is None:
        return {}
    available = calibration_set(calibration_dir)
    names = tuple(dict.fromkeys(names))
    options = {name: dict(available[name][1]["kwargs"]) for name in names if name in available}
    if names and not options:
        asked = repr(names[0]) if len(names) == 1 else f"any of {', '.join(names)}"
        raise ValueError(
            f"{calibration_dir} calibrates {sorted(available)}, not {asked}; calibrate it with "
            f"`lerobot-phantom-calibrate --attack NAME --measured PATH --out {calibration_dir}/NAME`"
        )
    return options


def calibrated_kwargs(name: str, calibration_dir: str | Path) -> dict[str, Any]:
    """Constructor options for attack ``name`` from ``calibration_dir`` (see ``calibration_set``)."""
    return calibrated_options([name], calibration_dir)[name]
