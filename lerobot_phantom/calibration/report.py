"""Writing the calibration's outputs: report.json, report.md (+ figures) and calibrated.json.

report.json (intervals are ``{estimate, low, high, level, draws}``: 90% percentile bootstrap over items; a
parameter's also has ``measured``, false when no refit moved it and the fit items do not depend on it,
identify.draw_intervals):

- ``attack``, ``input`` {path, kind, recording: the facts of the recording the models depend on, each with where
  it was read}, ``units``, ``n_fit``, ``n_heldout``, ``split`` {seed, items};
- ``heldout_scoring`` {definition, latent}: how held-out items are scored; ``latent`` names the per-frame
  quantity nobody can know in advance (None for inputs without one);
- ``base`` / ``extended``: {model, params, param_intervals, heldout_rmse (predictive), heldout_rmse_interval,
  [heldout_registered_rmse, heldout_expected_rmse] (latent inputs only)}; ``extended`` also has ``effects`` (the
  identified ones only: what calibrated.json carries) and ``derived``;
- ``gain`` {rmse_ratio, rmse_ratio_interval (paired over held-out items), rmse_reduction, selection_margin
  [, noise_scale_ratio]};
- ``selection`` {score, criterion, selected (forward selection on fit items), steps (validation_error: the score; the
  last step's without: the score without each effect no other builds on, without_pinned: per such effect the other
  selected effects a bound pins without it), rejected, not_offered {effect: reason}:
  candidates the fit items show no sign of, never tried (``Problem.unoffered``), set_aside_ahead [{group,
  validation_error, kept_validation_error, reason}]: groups the last step set aside though they scored the margin
  under the selected model (:func:`set_aside_ahead`), withdrawn [{effect, pass, reasons}]: effects an earlier pass
  selected and identification rejected on their own evidence, left out of the passes after it
  (identify.select_and_identify); ``selected`` and ``steps`` are the last pass's, earlier_passes [{pass, selected,
  withdrawn, steps}] those of each pass that withdrew one, form_passes [{without, selected, validation_error,
  first_selected, first_validation_error, taken, other_steps}] the last pass repeated without a simpler form of a term
  it took (core.select_forms; ``other_steps``: the steps of the pass not written)};
- ``identification``: per selected effect {effect, status "identified"/"not identified", identified, reasons, notes
  (parameters at their physical limit, and what keeps it from being shown redundant: not reasons), compared_steps (the
  two selection steps the ratio compares), validation_ratio (interval, fit items only), judged_with (the hosted
  effects whose gain the ratio includes), ratio_without (interval of the selected model without it to the selected
  model, where no other selected effect builds on it; else null), redundant (that is all it fails), gain_in_group (a
  change of form taken in one step with others: {others, interval} of the others alone to the group,
  identify.form_gains_in_groups),
  params, intervals, nulls} (rule:
  ``calibration/identify.py``); a cause implied by an identified effect's form (``Effect.implies``) has
  ``implied_by`` and its statistic as ``params`` (identify.implied_results); the simpler form of a term judged in
  place of a richer one that is not identified has ``in_place_of`` and ``scored`` {group, validation_error}
  (identify.simpler_form_result);
- ``findings``: identified effects only {effect, cause, evidence} (+ ``shot_noise`` when kept, see noise.py);
- ``unexplained_structure`` {structure_remains, summary, rule, tested_on, tests [{variable, statistic, value,
  interval, significant, where, ...}; frame pairs' ``variance_by_row`` / ``variance_by_column``: the variance beyond
  the sensor-noise model by position (structure.variance_tests); ``displacement_along_rows`` / ``_columns``: the
  share of the residual a displacement per line explains (read in each half of the line), ``displacement_px``
  (structure.displacement_tests); the outlying-item test: {variable "items", value,
  outlying_items, largest_fit_item_error, significant, where}]} (``calibration/structure.py``; ``tested_on`` says
  whether the fit items' cross-fitted residuals joined fewer than ``structure.MIN_TESTED_ITEMS`` held-out items);
- ``residual_analysis`` {base, extended}: binned held-out RMSE per variable; ``noise`` (frame pairs; with
  ``fit_items_structure`` {structure_remains, summary, tested_on, tests}, the fit pairs' cross-fitted residual
  tests, where conditions 1-4 of noise.py passed: structure.fit_items_structure);
  ``per_capture_heldout_rmse`` (laser captures).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from lerobot_phantom.calibration.core import SELECTION_SCORES, TIE_SHARE, Fit, FormPass, Problem, Step
from lerobot_phantom.calibration.identify import Interval, Selection, Withdrawal, error_ratio, rmse_interval
from lerobot_phantom.calibration.structure import MIN_TESTED_ITEMS, residual_structure

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


def heldout_scores(problem: Problem, fit: Fit, items: np.ndarray, *, rng) -> tuple[dict, np.ndarray]:
    """Held-out RMSE (predictive), its item-bootstrap interval, and for latent problems the registered RMSE."""
    squared, counts = problem.item_squared_errors(fit, items)
    scores = {
        "heldout_rmse": math.sqrt(float(squared.sum()) / max(float(counts.sum()), 1.0)),
        "heldout_rmse_interval": rmse_interval(squared, counts, rng=rng).as_dict(),
    }
    registered = problem.registered_squared_errors(fit, items)
    if registered is not None:
        expected = problem.expected_squared_errors(fit, items)
        for name, (sq, n) in (("registered", registered), ("expected", expected)):
            scores[f"heldout_{name}_rmse"] = math.sqrt(float(sq.sum()) / max(float(n.sum()), 1.0))
    return scores, squared


def build_report(
    problem: Problem,
    *,
    input_path: Path,
    fit_items: np.ndarray,
    heldout_items: np.ndarray,
    base: Fit,
    base_intervals: dict[str, Interval],
    selection: Selection,
    steps: list[Step],
    seed: int,
    margin: float,
    folds: int,
    withdrawn: Sequence[Withdrawal] = (),
) -> dict:
    """The report (schema in the module docstring)."""
    extended = selection.fit
    rng = np.random.default_rng([seed, 3])  # held-out statistics only: never feeds a fit
    base_scores, base_squared = heldout_scores(problem, base, heldout_items, rng=rng)
    ext_scores, ext_squared = heldout_scores(problem, extended, heldout_items, rng=rng)
    ratio = error_ratio(base_squared, ext_squared, rng=rng)
    findings = [
        finding(problem, result, steps, base, extended, fit_items)
        for result in selection.results
        if result["identified"]
    ]
    report = {
        "attack": problem.attack,
        "input": {
            "path": str(input_path),
            "kind": problem.input_kind,
            "recording": problem.recording_facts(),
        },
        "units": problem.units,
        "n_fit": len(fit_items),
        "n_heldout": len(heldout_items),
        "split": {"seed": seed, "items": problem.item_name},
        "heldout_scoring": {"definition": problem.heldout_definition, "latent": problem.latent},
        "base": {
            "model": problem.base_model,
            "params": base.params,
            "param_intervals": {k: v.as_dict() for k, v in base_intervals.items()},
            **base_scores,
        },
        "findings": findings,
        "identification": selection.results,
        "extended": {
            "model": problem.extended_model if extended.effects else problem.base_model,
            "effects": sorted(extended.effects),
            "params": extended.params,
            "param_intervals": {k: v.as_dict() for k, v in selection.intervals.items()},
            **ext_scores,
            "derived": problem.derived(extended),
        },
        "gain": {
            "rmse_ratio": base_scores["heldout_rmse"] / max(ext_scores["heldout_rmse"], 1e-12),
            "rmse_ratio_interval": ratio.as_dict(),
            "rmse_reduction": 1.0 - ext_scores["heldout_rmse"] / max(base_scores["heldout_rmse"], 1e-12),
            "selection_margin": margin,
        },
        "selection": selection_section(problem, selection, steps, withdrawn, margin=margin, folds=folds),
        "unexplained_structure": residual_structure(
            problem,
            extended,
            heldout_items,
            base_mse=base_scores["heldout_rmse"] ** 2,
            rng=np.random.default_rng([seed, 4]),
            fit_items=fit_items,
            folds=folds,
            seed=seed,
        ),
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


def finding(problem: Problem, result: dict, steps: list[Step], base: Fit, extended: Fit, fit_items) -> dict:
    """An identified effect's entry in ``findings``: its cause, and the evidence that names it."""
    effect = result["effect"]
    before, step = (steps[k] for k in result["compared_steps"])
    hosted = result.get("judged_with", [])
    implying, replaced = result.get("implied_by"), result.get("in_place_of")
    # a pair taken in one selection step (or effects selected between it and those it hosts) are in the ratio too:
    # the evidence names them
    together = sorted(set(step.effects) - set(before.effects) - {effect, replaced} - set(hosted))
    interval = result["validation_ratio"]
    # a simpler form in place of a richer one that is not identified: the score its own group had in that step
    after = result["scored"]["validation_error"] if replaced else step.validation_error
    evidence = (
        (f"the fitted form of {implying}, identified with " if implying else "")
        + (f"in place of {replaced} (not identified), the same term's simpler form, " if replaced else "")
        + f"inner validation {SELECTION_SCORES[problem.selection_score]} {before.validation_error:.3g} -> "
        f"{after:.3g} {problem.units} "
        + (f"with the effects it hosts ({', '.join(hosted)}) " if hosted else "")
        + (f"together with {', '.join(together)}, in the same comparison " if together else "")
        + f"(ratio {interval['estimate']:.3f}, {100 * interval['level']:.0f}% interval "
        f"{interval['low']:.3f}-{interval['high']:.3f}, fit items only)"
    )
    in_group = result.get("gain_in_group")
    if in_group:
        evidence += (
            f"; beside {in_group['others']}, taken with it: ratio {in_group['estimate']:.3f} "
            f"({in_group['low']:.3f}-{in_group['high']:.3f})"
        )
    without = result.get("ratio_without")
    if without:
        evidence += (
            f"; beside the other selected effects, the model without it: ratio {without['estimate']:.3f} "
            f"({without['low']:.3f}-{without['high']:.3f})"
        )
    # a parameter not measured has no interval to quote: its note says so
    measured = {k: v for k, v in result["intervals"].items() if v.get("measured") is not False}
    if measured:
        evidence += "; " + ", ".join(f"{k} = {v['estimate']:.4g} {_interval(v)}" for k, v in measured.items())
    if result.get("notes"):
        evidence += "; " + "; ".join(result["notes"])
    # the base's residual on the fit items; an implied cause has no term of its own to add to the base
    detail = None if implying else problem.evidence(effect, base, extended, fit_items)
    if detail:
        evidence += "; " + detail
    cause = next(e.cause for e in problem.candidates if e.name == effect)
    return {"effect": effect, "cause": cause, "evidence": evidence}


def selection_section(
    problem: Problem,
    selection: Selection,
    steps: list[Step],
    withdrawn: Sequence[Withdrawal],
    *,
    margin: float,
    folds: int,
) -> dict:
    """report.json's ``selection``: the criterion in words, the last pass's steps and what was withdrawn."""
    score_name = SELECTION_SCORES[problem.selection_score]
    criterion = (
        f"forward selection on the fit items by {folds}-fold cross-validated {score_name}"
        + (f" ({problem.selection_score_reason})" if problem.selection_score != "rmse" else "")
        + "; each kept "
        f"extension must lower it by >= {100 * margin:.0f}% (a group of up to {problem.joint_effects} "
        f"interacting extensions taken in one step: by >= {100 * margin:.0f}% per extension in it that does not "
        f"build on another of them, and by >= {100 * margin:.0f}% under the best smaller group nested in it or "
        "itself earning a step; a group is set "
        "aside when a member's own parameter sits at a bound of its range in most folds, and the richer of two "
        f"forms of one term is taken only by >= {100 * margin:.0f}% under the simpler one (where it is not, the "
        "group with the simpler form is not measured against the richer form's smaller groups); among groups whose "
        f"scores agree within a share of {TIE_SHARE:g}, which the fit items do not tell apart, "
        + (
            f"the one holding the earliest of {', '.join(problem.tie_preference)} ({problem.tie_preference_reason}), "
            "then the lowest"
            if problem.tie_preference
            else "the lowest"
        )
        + "); then each kept "
        "extension must pass the identification rule "
        "(calibration/identify.py): cross-validated error ratio interval above 1, and, where no other kept "
        "extension builds on it, that of the selected model without it to the selected model not wholly under "
        f"{1 + margin / 2:g} (half the gain a step must bring) unless without it another kept extension's own "
        "parameter sits at a bound in most folds, and for a change of form a step took with others, "
        "that of the others alone to the group above 1; no own parameter at a bound, an interval excluding "
        "its null value; a richer form that fails gives way to the simpler form "
        "scored beside it in the same step, judged by the same rule, and a cause a kept form implies is named "
        "when the interval of its statistic excludes the null value; an extension a pass selected and "
        "identification rejected on its own evidence is withdrawn and selection repeated without it (where the "
        "selected model without it is all that fails, only the one of them whose removal costs least); a pass "
        "that took the simpler of two forms of one term is repeated without that form, and the repeat is taken "
        f"when it holds a richer form and its last score is >= {100 * margin:.0f}% under the pass's"
    )
    return {
        "score": score_name,
        "criterion": criterion,
        "selected": selection.selected,
        "steps": [step_entry(s) for s in steps],
        "rejected": dict(steps[-1].tried),
        "not_offered": dict(selection.unoffered),
        "set_aside_ahead": set_aside_ahead(steps[-1], margin),
        "withdrawn": [w.as_dict() for w in withdrawn],
        "earlier_passes": earlier_passes(withdrawn),
        "form_passes": [form_pass_entry(p) for p in selection.form_passes],
    }


def set_aside_ahead(last: Step, margin: float) -> list[dict]:
    """The groups the last selection step set aside although they scored ``margin`` under the model selection kept,
    best first, with why: the fit items hold something a library term fits only at the end of its range (or in
    the richer of two forms without earning it), which the written model does not explain and no cause is named
    for (camsim's colour-correcting auto-exposure draw 1538857946: the meter, linear light and the matrix at 26.4
    against 48.4 kept, set aside with a matrix take at its bound 1, docs/bench/session71.md)."""
    ahead = sorted(
        (score, group)
        for group, score in last.tried.items()
        if group in last.set_aside and score <= (1.0 - margin) * last.validation_error
    )
    return [
        {
            "group": group,
            "validation_error": score,
            "kept_validation_error": last.validation_error,
            "reason": last.set_aside[group],
        }
        for score, group in ahead
    ]


def form_pass_entry(form_pass: FormPass) -> dict:
    """A selection pass repeated without a simpler form, as report.json's ``selection.form_passes`` holds it."""
    return {
        "without": form_pass.without,
        "selected": form_pass.selected,
        "validation_error": form_pass.validation_error,
        "first_selected": form_pass.first_selected,
        "first_validation_error": form_pass.first_validation_error,
        "taken": form_pass.taken,
        "other_steps": [step_entry(s) for s in form_pass.other_steps],
    }


def step_entry(step: Step) -> dict:
    """A selection step as report.json's ``selection.steps`` holds it."""
    return {
        "effects": step.effects,
        "validation_error": step.validation_error,
        "tried": step.tried,
        "set_aside": step.set_aside,
        "tied": step.tied,
        # the last step's: the selected model's score without each effect no other builds on (identify.Redundancy)
        "without": step.without,
        "without_pinned": step.without_pinned,
    }


def earlier_passes(withdrawn: Sequence[Withdrawal]) -> list[dict]:
    """Every pass that withdrew an effect, in order: what it selected, what it withdrew and its steps."""
    passes: dict[int, dict] = {}
    for withdrawal in withdrawn:
        entry = passes.setdefault(
            withdrawal.selection_pass,
            {
                "pass": withdrawal.selection_pass,
                "selected": sorted(withdrawal.pass_steps[-1].effects),
                "withdrawn": [],
                "steps": [step_entry(s) for s in withdrawal.pass_steps],
            },
        )
        entry["withdrawn"].append(withdrawal.effect)
    return [passes[k] for k in sorted(passes)]


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
    lines = (
        _problem_lines(report)
        + _cause_lines(report)
        + _structure_lines(report["unexplained_structure"])
        + _extended_lines(report)
        + (_noise_lines(report["noise"]) if "criterion" in report.get("noise", {}) else [])
        + _selection_lines(report["selection"])
        + ["", "## Figures", ""]
        + [f"![{name}]({name})" for name in figures]
        + [""]
    )
    path.write_text("\n".join(lines))


def _problem_lines(report: dict) -> list[str]:
    """The input, the split, and the base model's held-out error."""
    units = report["units"]
    base, ext = report["base"], report["extended"]
    return [
        f"# Calibration of `{report['attack']}` against measured data",
        "",
        f"Input: `{report['input']['path']}` ({report['input']['kind']}); {report['n_fit']} {report['split']['items']} "
        f"fitted, {report['n_heldout']} held out (seed {report['split']['seed']}). Errors are RMSE in {units}."
        + (
            f" Over only {report['n_heldout']} held-out items, the held-out intervals below are item bootstraps"
            " whose ends lie at or near single items' values, not confidence intervals; the evidence for each"
            " effect is its validation ratio over the fit items."
            if report["n_heldout"] < MIN_TESTED_ITEMS
            else ""
        )
        + "".join(f" {k.replace('_', ' ')}: {v}." for k, v in report["input"]["recording"].items()),
        "",
        "## What the simulation gets wrong",
        "",
        f"The paper's simulation ({base['model']}) fitted by least squares errs by **{base['heldout_rmse']:.3g}** "
        f"{_interval(base['heldout_rmse_interval'])} {units} on held-out data.",
        "",
        f"Held-out scoring: {report['heldout_scoring']['definition']}."
        + (
            f" Per-frame latent: {report['heldout_scoring']['latent']}. Registered (latent fitted on each held-out "
            f"frame, for comparison only): base {base['heldout_registered_rmse']:.3g}, extended "
            f"{ext['heldout_registered_rmse']:.3g}; expected over the latent's prior (a point prediction made "
            f"without the frame): base {base['heldout_expected_rmse']:.3g}, extended "
            f"{ext['heldout_expected_rmse']:.3g}."
            if report["heldout_scoring"]["latent"]
            else ""
        ),
        "",
    ]


def _cause_lines(report: dict) -> list[str]:
    """The named causes with their evidence, then the selected effects that were not identified and why."""
    lines = []
    if report["findings"]:
        lines.append("Named causes (selected on the fit items and identified by the rule below):")
        lines.append("")
        for finding in report["findings"]:
            lines.append(f"- **`{finding['effect']}`**: {finding['cause']}. Evidence: {finding['evidence']}.")
    else:
        lines.append("No extension was both selected and identified: the base model is kept.")
    ahead = report["selection"].get("set_aside_ahead", [])
    if ahead:
        lines += [
            "",
            f"Set aside although they fit the items better than the selected model ({report['selection']['score']} "
            f"{ahead[0]['kept_validation_error']:.3g}): what they capture is left unexplained, not named:",
            "",
        ]
        lines += [f"- `{a['group']}`: {a['validation_error']:.3g}; {a['reason']}" for a in ahead]
    not_identified = [r for r in report["identification"] if not r["identified"]]
    # an implied cause was never selected: it is listed under the form that implies it
    selected = [r for r in not_identified if not r.get("implied_by")]
    implied = [r for r in not_identified if r.get("implied_by")]
    if selected:
        lines += ["", "Selected but **not identified** (not a named cause, not in the written model):", ""]
        lines += [f"- `{r['effect']}`: " + "; ".join(r["reasons"]) for r in selected]
    if implied:
        lines += ["", "Implied by an identified form but **not identified** (not a named cause):", ""]
        lines += [
            f"- `{r['effect']}`, implied by `{r['implied_by']}`: " + "; ".join(r["reasons"]) for r in implied
        ]
    return lines


def _structure_lines(structure: dict) -> list[str]:
    return [
        "",
        "## Unexplained structure",
        "",
        structure["summary"] + ".",
        "",
        f"Tested on: {structure['tested_on']}.",
        "",
        f"Rule: {structure['rule']}.",
    ]


def _extended_lines(report: dict) -> list[str]:
    """The written model, its held-out error against the base's, its parameters and derived quantities."""
    units = report["units"]
    base, ext, gain = report["base"], report["extended"], report["gain"]
    lines = [
        "",
        "## Extended model and gain",
        "",
        f"Extended model: {ext['model']} with effects {', '.join(f'`{e}`' for e in ext['effects']) or '(none)'}.",
        f"Held-out RMSE **{ext['heldout_rmse']:.3g}** {_interval(ext['heldout_rmse_interval'])} {units} vs "
        f"**{base['heldout_rmse']:.3g}** for the base: ratio {gain['rmse_ratio']:.2f} "
        f"{_interval(gain['rmse_ratio_interval'])} ({100 * gain['rmse_reduction']:.0f}% lower).",
        "",
        "Fitted parameters (90% item-bootstrap intervals): "
        + ", ".join(
            f"`{k}` = {_fmt(v)} {_interval(ext['param_intervals'].get(k))}" for k, v in ext["params"].items()
        ),
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
    return lines


def _noise_lines(noise: dict) -> list[str]:
    """The noise model's verdict and fit (noise.py)."""
    relative_sd = noise["multiplicative_relative_sd"]
    return [
        "",
        "## Noise model (`shot_noise`)",
        "",
        "Noise cannot be predicted pixel by pixel and never lowers an RMSE, so `shot_noise` is judged as a "
        "model of the residual's distribution instead: " + noise["criterion"] + ". "
        f"Inner validation noise-scale ratio {noise['validation_noise_scale_ratio']:.3f}, held out "
        f"{noise['heldout_noise_scale_ratio']:.3f}: "
        + ("kept" if noise["kept"] else "not kept (" + "; ".join(noise["reasons"]) + ")")
        + f". Tone curve that linearises the frames: {noise['tone_curve']}. Fitted, in linear-light grey "
        "levels (linear light x 255, before the tone curve): read noise "
        f"{noise['shot_noise']['read_noise_grey']:.3g}, shot gain {noise['shot_noise']['shot_gain_grey']:.3g} "
        "(variance per unit of signal); beside a multiplicative term, the light's relative sd "
        f"{relative_sd['estimate']:.3g} ({100 * relative_sd['level']:.0f}% interval {relative_sd['low']:.3g}-"
        f"{relative_sd['high']:.3g}). Held-out residual RMSE (output grey levels) vs predicted signal "
        "(linear-light grey levels): "
        + ", ".join(
            f"{x:.0f}: {r:.2f}"
            for x, r in zip(
                noise["residual_vs_signal"]["x"], noise["residual_vs_signal"]["rmse"], strict=True
            )
        )
        + ".",
    ]


def _selection_lines(selection: dict) -> list[str]:
    """The criterion, what was withdrawn, and every step with the candidates it tried."""
    lines = ["", "## Selection", "", selection["criterion"] + ".", ""]
    for effect, reason in selection.get("not_offered", {}).items():
        lines.append(f"- not offered: `{effect}` ({reason})")
    for withdrawal in selection["withdrawn"]:
        lines.append(
            f"- withdrawn after pass {withdrawal['pass']}: `{withdrawal['effect']}`, not identified ("
            + "; ".join(withdrawal["reasons"])
            + ")"
        )
    for form_pass in selection.get("form_passes", []):
        lines.append(
            f"- repeated without `{form_pass['without']}`, the simpler form of a term: selected "
            f"{form_pass['selected']} at {form_pass['validation_error']:.4g}, against {form_pass['first_selected']} "
            f"at {form_pass['first_validation_error']:.4g}; "
            + (
                "taken (its steps are below; those of the pass it replaced are in report.json)"
                if form_pass["taken"]
                else "not taken"
            )
        )
    passes = selection.get("earlier_passes", [])
    for earlier in passes:
        lines.append(
            f"- pass {earlier['pass']} selected {earlier['selected']} and withdrew {earlier['withdrawn']}; its steps:"
        )
        lines += ["  " + line for line in _step_lines(earlier["steps"], selection["score"])]
    if not passes:
        return lines + _step_lines(selection["steps"], selection["score"])
    lines.append(f"- pass {passes[-1]['pass'] + 1}, the last, whose model is written; its steps:")
    return lines + ["  " + line for line in _step_lines(selection["steps"], selection["score"])]


def _step_lines(steps: list[dict], score: str) -> list[str]:
    """One line per selection step: its score, the candidates it tried and a tie it was taken over."""
    lines = []
    for step in steps:
        set_aside = step["set_aside"]
        tried = ", ".join(
            f"{k}: {v:.3g}" + (f" (not eligible: {set_aside[k]})" if k in set_aside else "")
            for k, v in step["tried"].items()
        )
        tied = step["tied"]
        lines.append(
            f"- {step['effects'] or ['base']}: validation {score} {step['validation_error']:.3g}"
            + (f"; candidates tried next: {tried}" if tried else "")
            + (
                f"; the step taken tied with {', '.join(tied)} (not told apart by the fit items)"
                if tied
                else ""
            )
        )
    return lines


def _interval(interval: dict | None) -> str:
    if not interval or interval.get("low") is None:
        return ""
    if interval.get("measured") is False:
        return "(not measured: the fit items do not depend on it)"
    return f"[{interval['low']:.4g}, {interval['high']:.4g}]"


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
