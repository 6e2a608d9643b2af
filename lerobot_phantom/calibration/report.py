"""Writing the calibration's outputs: report.json, report.md (+ figures) and calibrated.json."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import Fit, Problem, Step

CALIBRATED_FILE = "calibrated.json"
CALIBRATED_FORMAT = 1


def _clean(value):
    """JSON-safe copy (numpy scalars -> floats, non-finite -> None)."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def build_report(
    problem: Problem,
    *,
    input_path: Path,
    fit_items: np.ndarray,
    heldout_items: np.ndarray,
    chain: list[Fit],
    steps: list[Step],
    seed: int,
    margin: float,
    folds: int,
) -> dict:
    base, extended = chain[0], chain[-1]
    base_rmse = problem.rmse(base, heldout_items)
    extended_rmse = problem.rmse(extended, heldout_items)
    findings = []
    for k, (before_step, after_step) in enumerate(itertools.pairwise(steps)):
        (effect,) = set(after_step.effects) - set(before_step.effects)
        previous, after = chain[k], chain[k + 1]
        cause = next(e.cause for e in problem.candidates if e.name == effect)
        evidence = (
            f"inner validation RMSE {before_step.validation_rmse:.3g} -> {after_step.validation_rmse:.3g} "
            f"{problem.units} ({100 * (1 - after_step.validation_rmse / before_step.validation_rmse):.1f}% lower); "
            + problem.evidence(effect, previous, after, fit_items)
        )
        findings.append({"effect": effect, "cause": cause, "evidence": evidence})
    rejected = steps[-1].tried
    report = {
        "attack": problem.attack,
        "input": {"path": str(input_path), "kind": problem.input_kind},
        "units": problem.units,
        "n_fit": len(fit_items),
        "n_heldout": len(heldout_items),
        "split": {"seed": seed, "items": _item_name(problem)},
        "base": {"model": problem.base_model, "params": base.params, "heldout_rmse": base_rmse},
        "findings": findings,
        "extended": {
            "model": problem.extended_model if extended.effects else problem.base_model,
            "effects": [s for s in steps[-1].effects],
            "params": extended.params,
            "heldout_rmse": extended_rmse,
            "derived": problem.derived(extended),
        },
        "gain": {
            "rmse_ratio": base_rmse / max(extended_rmse, 1e-12),
            "rmse_reduction": 1.0 - extended_rmse / max(base_rmse, 1e-12),
            "selection_margin": margin,
        },
        "selection": {
            "criterion": f"forward selection on the fit split by {folds}-fold cross-validated RMSE; each kept "
            f"extension must lower it by >= {100 * margin:.0f}% (a pair of interacting extensions by "
            f">= {200 * margin:.0f}%)",
            "steps": [
                {"effects": s.effects, "validation_rmse": s.validation_rmse, "tried": s.tried} for s in steps
            ],
            "rejected": {k: v for k, v in rejected.items()},
        },
        "residual_analysis": {
            "base": problem.analyse(base, heldout_items),
            "extended": problem.analyse(extended, heldout_items),
        },
    }
    if hasattr(problem, "per_capture_rmse"):
        report["per_capture_heldout_rmse"] = {
            "base": problem.per_capture_rmse(base, heldout_items),
            "extended": problem.per_capture_rmse(extended, heldout_items),
        }
    return _clean(report)


def _item_name(problem: Problem) -> str:
    return {
        "stripe_table": "table rows",
        "colour_triples": "table rows",
        "laser_captures": "8x8-pixel tiles (captures resized to at most 128 px)",
        "frame_pairs": "whole image pairs",
    }.get(problem.input_kind, "items")


def calibrated_payload(problem: Problem, extended: Fit, report: dict) -> dict:
    return _clean(
        {
            "format": CALIBRATED_FORMAT,
            "attack": problem.attack,
            "effects": sorted(extended.effects),
            "kwargs": problem.transform_kwargs(extended),
            "params": extended.params,
            "derived": report["extended"]["derived"],
            "heldout_rmse": report["extended"]["heldout_rmse"],
            "source": report["input"],
        }
    )


def plot_analysis(report: dict, out_dir: Path) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    analysis = report["residual_analysis"]
    variables = [v for v in analysis["base"] if "rmse" in analysis["base"][v]]
    if not variables:
        return []
    cols = min(3, len(variables))
    rows = -(-len(variables) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.5 * cols, 3.3 * rows), squeeze=False)
    for ax, variable in zip(axes.ravel(), variables, strict=False):
        for which, style in (("base", "o-"), ("extended", "s-")):
            data = analysis[which].get(variable)
            if data:
                ax.plot(data["x"], data["rmse"], style, ms=3, label=which)
        ax.set(xlabel=variable, ylabel=f"held-out RMSE ({report['units']})")
        ax.legend(fontsize=7)
    for ax in axes.ravel()[len(variables) :]:
        ax.axis("off")
    fig.suptitle("residual vs variable (held-out)")
    fig.tight_layout()
    path = out_dir / "residual_vs_variables.png"
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return [path.name]


def write_markdown(report: dict, figures: list[str], path: Path) -> None:
    units = report["units"]
    base, ext, gain = report["base"], report["extended"], report["gain"]
    lines = [
        f"# Calibration of `{report['attack']}` against measured data",
        "",
        f"Input: `{report['input']['path']}` ({report['input']['kind']}); {report['n_fit']} {report['split']['items']} "
        f"fitted, {report['n_heldout']} held out (seed {report['split']['seed']}). Errors are RMSE in {units}.",
        "",
        "## What the simulation gets wrong",
        "",
        f"The paper's simulation ({base['model']}) fitted by least squares errs by **{base['heldout_rmse']:.3g}** "
        f"{units} on held-out data.",
        "",
    ]
    if report["findings"]:
        lines.append("Named causes, in the order forward selection kept them:")
        lines.append("")
        for finding in report["findings"]:
            lines.append(f"- **`{finding['effect']}`**: {finding['cause']}. Evidence: {finding['evidence']}.")
    else:
        lines.append(
            "No extension lowered the validation error by the required margin: the base model is kept "
            "(its residual is noise the library cannot explain)."
        )
    lines += [
        "",
        "## Extended model and gain",
        "",
        f"Extended model: {ext['model']} with effects {', '.join(f'`{e}`' for e in ext['effects']) or '(none)'}.",
        f"Held-out RMSE **{ext['heldout_rmse']:.3g}** {units} vs **{base['heldout_rmse']:.3g}** for the base: "
        f"ratio {gain['rmse_ratio']:.2f} ({100 * gain['rmse_reduction']:.0f}% lower).",
        "",
        "Fitted parameters: " + ", ".join(f"`{k}` = {_fmt(v)}" for k, v in ext["params"].items()),
        "",
    ]
    derived = {k: v for k, v in ext.get("derived", {}).items() if k != "captures"}
    if derived:
        lines.append("Derived quantities: " + ", ".join(f"`{k}` = {_fmt(v)}" for k, v in derived.items()))
        lines.append("")
    for capture in ext.get("derived", {}).get("captures", []):
        lines.append(
            f"- `{capture['capture']}`: "
            + ", ".join(f"{k} = {_fmt(v)}" for k, v in capture.items() if k != "capture")
        )
    if "per_capture_heldout_rmse" in report:
        lines += ["", "| capture | base RMSE | extended RMSE |", "|---|---|---|"]
        per = report["per_capture_heldout_rmse"]
        for name, value in per["base"].items():
            lines.append(f"| {name} | {value:.2f} | {per['extended'][name]:.2f} |")
    if "noise" in report and "criterion" in report["noise"]:
        noise = report["noise"]
        lines += [
            "",
            "## Noise model (`shot_noise`)",
            "",
            "Noise cannot be predicted pixel by pixel and never lowers an RMSE, so `shot_noise` is judged as a "
            "model of the residual's distribution instead: " + noise["criterion"] + ". "
            f"Inner validation noise-scale ratio {noise['validation_noise_scale_ratio']:.3f}, held out "
            f"{noise['heldout_noise_scale_ratio']:.3f}: "
            + (
                "kept"
                if noise["kept"]
                else "not kept (the residual's variance does not depend on the signal)"
            )
            + f". Fitted: read noise {noise['shot_noise']['read_noise_grey']:.3g} grey levels, shot gain "
            f"{noise['shot_noise']['shot_gain_grey']:.3g} grey levels^2 per grey level. Held-out residual RMSE vs "
            "predicted signal: "
            + ", ".join(
                f"{x:.0f}: {r:.2f}"
                for x, r in zip(
                    noise["residual_vs_signal"]["x"], noise["residual_vs_signal"]["rmse"], strict=True
                )
            )
            + ".",
        ]
    lines += ["", "## Selection", "", report["selection"]["criterion"] + ".", ""]
    for step in report["selection"]["steps"]:
        tried = ", ".join(f"{k}: {v:.3g}" for k, v in step["tried"].items())
        lines.append(
            f"- {step['effects'] or ['base']}: validation RMSE {step['validation_rmse']:.3g}"
            + (f"; candidates tried next: {tried}" if tried else "")
        )
    lines += ["", "## Figures", ""]
    lines += [f"![{name}]({name})" for name in figures]
    lines.append("")
    path.write_text("\n".join(lines))


def _fmt(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list):
        return "[" + ", ".join(_fmt(v) for v in value) + "]"
    return str(value)


def write_outputs(
    problem: Problem, report: dict, base: Fit, extended: Fit, heldout: np.ndarray, out: Path
) -> None:
    out.mkdir(parents=True, exist_ok=True)
    figures = problem.figures(base, extended, heldout, out) + plot_analysis(report, out)
    (out / "report.json").write_text(json.dumps(report, indent=2))
    write_markdown(report, figures, out / "report.md")
    (out / CALIBRATED_FILE).write_text(json.dumps(calibrated_payload(problem, extended, report), indent=2))
