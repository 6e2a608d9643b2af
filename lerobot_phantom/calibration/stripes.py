"""Stripe tables -> ``laser_color_strip``: how many rows a pulsed laser lights in a rolling-shutter camera.

Base (the paper): a fixed band of rows whatever the laser and exposure settings (fitted height; the paper uses
H/3). Extensions follow the rolling shutter: a row is lit when its exposure window overlaps a laser pulse.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from lerobot_phantom.calibration.core import Effect, Fit, Param, Problem, binned_rmse, fit_least_squares
from lerobot_phantom.transforms.physics import rolling_shutter_rows_lit

STRIPE_COLUMNS = ("frequency", "exposure", "duty_cycle", "affected_rows_mean")

EFFECTS = (
    Effect(
        "exposure_overlap",
        "a rolling shutter exposes rows one after another; a row is lit when its exposure window overlaps a laser "
        "pulse, so the stripe spans (pulse on-time + exposure time) / row time rows instead of a fixed band",
    ),
    Effect(
        "integration_offset",
        "the sensor integrates light a little longer than the nominal exposure setting (a constant extra "
        "integration time per row), widening every stripe by the same number of rows",
        requires=("exposure_overlap",),
    ),
    Effect(
        "stripe_period",
        "when the laser period is shorter than the frame readout, stripes repeat every 1 / (frequency x row "
        "time) rows, so the lit share of the frame saturates",
        requires=("exposure_overlap",),
    ),
    Effect(
        "edge_ramp",
        "rows at a stripe's edges catch only part of a pulse (a ramp of brightness); rows below the detection "
        "threshold are not counted, shrinking stripes by a share of the shorter of pulse and exposure",
        requires=("exposure_overlap",),
    ),
)


def _number(value, what: str) -> float:
    if isinstance(value, int | float | np.number):
        return float(value)
    match = re.search(r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?", str(value))
    if match is None:
        raise ValueError(f"cannot read a number from {what} value {value!r}")
    return float(match.group())


def is_stripe_table(columns) -> bool:
    return set(STRIPE_COLUMNS) <= set(columns)


class StripeProblem(Problem):
    attack = "laser_color_strip"
    input_kind = "stripe_table"
    units = "rows"
    base_model = "fixed band of rows (the paper's laser color strip, band height fitted)"
    extended_model = "rolling-shutter pulse/exposure overlap"
    candidates = EFFECTS

    def __init__(self, path: Path, *, image_height: int, exposure_unit_s: float) -> None:
        table = pd.read_csv(path)
        missing = [c for c in STRIPE_COLUMNS if c not in table.columns]
        if missing:
            raise ValueError(f"{path}: stripe table lacks columns {missing}; needs {list(STRIPE_COLUMNS)}")
        if image_height <= 0 or exposure_unit_s <= 0:
            raise ValueError("--image-height and --exposure-unit-s must be positive")
        self.path = path
        self.image_height = int(image_height)
        self.exposure_unit_s = float(exposure_unit_s)
        self.frequency_hz = np.array([_number(v, "frequency") for v in table["frequency"]])
        self.exposure_setting = np.array([_number(v, "exposure") for v in table["exposure"]])
        self.duty = np.array([_number(v, "duty_cycle") for v in table["duty_cycle"]]) / 100.0
        self.rows = table["affected_rows_mean"].to_numpy(dtype=np.float64)
        if (self.frequency_hz <= 0).any() or not np.isfinite(self.rows).all():
            raise ValueError(f"{path}: frequencies must be positive and row counts finite")
        self.exposure_s = self.exposure_setting * self.exposure_unit_s

    @property
    def n_items(self) -> int:
        return len(self.rows)

    # -- model ---------------------------------------------------------------------------------------------
    def param_specs(self, effects: frozenset[str]) -> list[Param]:
        height = self.image_height
        if "exposure_overlap" not in effects:
            return [Param("band_rows", height / 3.0, 0.0, float(height), scale=height / 3.0)]
        # a full-frame readout in ~1/30 s is typical; the bounds allow 1 us .. 10 ms per row
        row_time = 1.0 / (30.0 * height)
        specs = [Param("row_time_s", row_time, 1e-6, 1e-2, scale=row_time)]
        if "integration_offset" in effects:
            specs.append(Param("integration_offset_s", 0.0, -0.05, 0.05, scale=1e-3))
        if "edge_ramp" in effects:
            specs.append(Param("edge_threshold", 0.1, 0.0, 0.5, scale=0.1))
        return specs

    def predict(self, effects: frozenset[str], params: dict, items: np.ndarray) -> torch.Tensor:
        if "exposure_overlap" not in effects:
            return torch.as_tensor(params["band_rows"], dtype=torch.float64).expand(len(items))
        return rolling_shutter_rows_lit(
            torch.as_tensor(self.frequency_hz[items]),
            torch.as_tensor(self.duty[items]),
            torch.as_tensor(self.exposure_s[items]),
            params["row_time_s"],
            image_rows=self.image_height,
            integration_offset_s=params.get("integration_offset_s", 0.0),
            edge_threshold=params.get("edge_threshold", 0.0),
            periodic="stripe_period" in effects,
        )

    def fit(self, effects: frozenset[str], items: np.ndarray, start: Fit | None = None) -> Fit:
        target = torch.as_tensor(self.rows[items])
        params = fit_least_squares(
            self.param_specs(effects),
            lambda p: self.predict(effects, p, items) - target,
            warm=None if start is None else start.params,
        )
        return Fit(effects, params)

    def residual(self, fit: Fit, items: np.ndarray) -> np.ndarray:
        return self.predict(fit.effects, fit.params, items).numpy() - self.rows[items]

    def squared_errors(self, fit: Fit, items: np.ndarray) -> tuple[float, int]:
        residual = self.residual(fit, items)
        return float(np.sum(residual**2)), len(items)

    # -- reporting -----------------------------------------------------------------------------------------
    def analyse(self, fit: Fit, items: np.ndarray) -> dict:
        residual = self.residual(fit, items)
        return {
            "exposure_s": binned_rmse(self.exposure_s[items], residual),
            "duty": binned_rmse(self.duty[items], residual),
            "frequency_hz": binned_rmse(self.frequency_hz[items], residual),
            "signed_residual_vs_on_plus_exposure_s": {
                "x": (self.duty[items] / self.frequency_hz[items] + self.exposure_s[items]).tolist(),
                "residual": residual.tolist(),
            },
        }

    def evidence(self, effect: str, before: Fit, after: Fit, items: np.ndarray) -> str:
        res = self.residual(before, items)
        drivers = {
            "exposure_overlap": self.duty[items] / self.frequency_hz[items] + self.exposure_s[items],
            "integration_offset": self.exposure_s[items],
            "stripe_period": self.duty[items],
            "edge_ramp": np.minimum(self.duty[items] / self.frequency_hz[items], self.exposure_s[items]),
        }
        driver = drivers[effect]
        corr = float(np.corrcoef(driver, res)[0, 1]) if np.std(driver) > 0 and np.std(res) > 0 else 0.0
        return (
            f"before {effect}: residual mean {np.mean(res):+.1f} rows, correlation with its driving variable "
            f"{corr:+.2f}"
        )

    def derived(self, fit: Fit) -> dict:
        if "row_time_s" not in fit.params:
            return {"band_fraction": fit.params["band_rows"] / self.image_height}
        row_time = fit.params["row_time_s"]
        return {
            "row_time_us": row_time * 1e6,
            "frame_readout_ms": row_time * self.image_height * 1e3,
            "integration_offset_us": fit.params.get("integration_offset_s", 0.0) * 1e6,
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
            "edge_threshold": fit.params.get("edge_threshold", 0.0),
        }

    def figures(self, base: Fit, extended: Fit, items: np.ndarray, out_dir: Path) -> list[str]:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        everything = np.arange(self.n_items)
        x = self.duty[everything] * 100
        fig, axes = plt.subplots(1, 2, figsize=(11, 4))
        for exposure in np.unique(self.exposure_setting):
            sel = np.where(self.exposure_setting == exposure)[0]
            sel = sel[np.argsort(x[sel])]
            line = axes[0].plot(x[sel], self.rows[sel], "o", ms=4, label=f"exposure {exposure:g}")[0]
            axes[0].plot(
                x[sel],
                self.predict(extended.effects, extended.params, sel).numpy(),
                "-",
                color=line.get_color(),
            )
        axes[0].axhline(base.params.get("band_rows", np.nan), color="k", ls="--", label="base (fixed band)")
        axes[0].set(xlabel="duty cycle (%)", ylabel="rows lit", title="measured (dots) vs extended (lines)")
        axes[0].legend(fontsize=7)
        for fit, label in ((base, "base"), (extended, "extended")):
            res = self.residual(fit, items)
            axes[1].plot(self.duty[items] * 100, res, "o", label=label)
        axes[1].axhline(0, color="k", lw=0.5)
        axes[1].set(xlabel="duty cycle (%)", ylabel="residual (rows), held-out", title="held-out residuals")
        axes[1].legend()
        fig.tight_layout()
        path = out_dir / "stripes_fit.png"
        fig.savefig(path, dpi=100)
        plt.close(fig)
        return [path.name]
