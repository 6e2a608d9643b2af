"""The camera attacks' cost per intensity level, averaged over the attacks, with paired bootstrap intervals.

A row of Table 3 or Table 5 is one condition of ~50 episodes, where a change of +-12 pp is noise (p ~ 0.1). The
questions a study answers are about averages over the six camera attacks (paper Sec. "Experiments", Table 5: AT
"regains" TSR at medium): how much do they cost at each level, how much of that does training win back, at what cost
on clean data, and does it beat a rate-0 control. Every condition of a sweep runs the same episodes (task, env seed),
so per episode the mean success over a level's attacks is paired with the clean run of that episode, and with the
same episode under another policy. Intervals resample episodes: 95 % percentile bootstrap (``scipy.stats.bootstrap``,
10 000 resamples, a fixed seed so that a report is reproducible).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.stats import bootstrap

from lerobot_phantom.eval.results import CLEAN
from lerobot_phantom.eval.tables import Table
from lerobot_phantom.transforms.intensity import LEVELS
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS

if TYPE_CHECKING:
    from lerobot_phantom.eval.report import EvalRun

INTERVAL = "95% paired percentile bootstrap over episodes"
RESAMPLES = 10_000
BOOTSTRAP_SEED = 0
COST_NOTE = (
    "Cells: mean drop of task success rate (TSR) from clean to attacked, in percentage points (pp), averaged over the "
    f"camera attacks evaluated at that level (all six unless the cell names fewer), with its {INTERVAL}. The clean row is TSR %."
)
CHANGE_NOTE = (
    "Cells: paired change after - before of the TSR averaged over the level's camera attacks, in pp with its "
    f"{INTERVAL}; after 'of', the mean drop (pp) from clean before training at that level, then in parentheses the "
    "share of it won back (change / drop, when the drop is positive). The clean row is the change of clean TSR."
)


def level_conditions(run: EvalRun, level: str) -> list[str]:
    """The camera-attack conditions of a run at one named level (``laser_blinding@medium``, ...)."""
    return [f"{attack}@{level}" for attack in CAMERA_ATTACKS if f"{attack}@{level}" in run.conditions]


def success_matrix(run: EvalRun, conditions: list[str], suite: str, keys: list) -> np.ndarray:
    """Successes as a (conditions, episodes) float array, episodes in the order of ``keys``."""
    rows = []
    for condition in conditions:
        episodes = run.episodes(condition, suite)
        if set(episodes) != set(keys):
            raise ValueError(
                f"{run.path}: {condition} on {suite} ran other episodes than its clean control; a level average "
                "pairs every attack with the clean run of the same (task, seed)"
            )
        rows.append([float(episodes[k]) for k in keys])
    return np.asarray(rows, dtype=float)


def mean_interval(values: np.ndarray) -> tuple[float, float, float]:
    """(mean, low, high) with the percentile bootstrap over the values (episodes)."""
    mean = float(values.mean())
    if np.all(values == values[0]):
        return mean, mean, mean  # a resample of identical values has no spread
    result = bootstrap(
        (values,),
        np.mean,
        n_resamples=RESAMPLES,
        confidence_level=0.95,
        method="percentile",
        rng=np.random.default_rng(BOOTSTRAP_SEED),
    )
    return mean, float(result.confidence_interval.low), float(result.confidence_interval.high)


def per_episode_level_tsr(run: EvalRun, suite: str, keys: list) -> dict[str, tuple[np.ndarray, int]]:
    """Level -> (per-episode mean success over the level's camera attacks, number of attacks), clean included."""
    out = {CLEAN: (success_matrix(run, [CLEAN], suite, keys)[0], 1)}
    for level in LEVELS:
        conditions = level_conditions(run, level)
        if conditions:
            out[level] = (success_matrix(run, conditions, suite, keys).mean(axis=0), len(conditions))
    return out


def attack_count(n_attacks: int) -> str:
    """Marks an average over fewer than all camera attacks (a leave-one-out or calibrated-physics sweep)."""
    return "" if n_attacks == len(CAMERA_ATTACKS) else f" ({n_attacks} of {len(CAMERA_ATTACKS)} attacks)"


def pp_cell(mean: float, low: float, high: float) -> str:
    return f"{100 * mean:+.1f} [{100 * low:+.1f}, {100 * high:+.1f}]"


def level_rows(cells: dict[str, list[str]]) -> list[tuple[str, list[str]]]:
    return [(CLEAN, cells[CLEAN])] + [(f"camera attacks, {level}", cells[level]) for level in LEVELS]


def level_costs(runs: list[EvalRun]) -> tuple[Table, list[dict[str, Any]]]:
    """Rows clean + levels, one column per run x suite: the mean cost of the camera attacks with its interval."""
    groups, columns, records = [], [], []
    cells: dict[str, list[str]] = {CLEAN: [], **{level: [] for level in LEVELS}}
    for run in runs:
        groups.append((run.label if len(runs) > 1 else "", len(run.suites)))
        columns += run.suites
        for suite in run.suites:
            keys = sorted(run.episodes(CLEAN, suite), key=str)
            if not keys:
                for row in cells.values():
                    row.append("-")
                continue
            tsr = per_episode_level_tsr(run, suite, keys)
            clean, _ = tsr[CLEAN]
            cells[CLEAN].append(f"{100 * clean.mean():.1f}")
            for level in LEVELS:
                if level not in tsr:
                    cells[level].append("-")
                    continue
                attacked, n_attacks = tsr[level]
                mean, low, high = mean_interval(clean - attacked)
                cells[level].append(pp_cell(mean, low, high) + attack_count(n_attacks))
                records.append(
                    {
                        "run": run.label,
                        "suite": suite,
                        "level": level,
                        "attacks": n_attacks,
                        "episodes": len(keys),
                    }
                    | {"clean_tsr": float(clean.mean()), "attacked_tsr": float(attacked.mean())}
                    | {"drop": mean, "ci_low": low, "ci_high": high}
                )
    table = Table(groups, columns, level_rows(cells), corner="Level", notes=(COST_NOTE,), unit="pp")
    return table, records


def level_changes(pairs: list[tuple[EvalRun, EvalRun]]) -> tuple[Table, list[dict[str, Any]]]:
    """Rows clean + levels, one column per before/after pair x suite: the paired change of the level's mean TSR,
    the drop before training it is measured against, and the share won back. Pairs must already be checked
    (``report.check_pair``)."""
    groups, columns, records = [], [], []
    cells: dict[str, list[str]] = {CLEAN: [], **{level: [] for level in LEVELS}}
    for before, after in pairs:
        groups.append((f"{after.label} vs {before.label}" if len(pairs) > 1 else "", len(before.suites)))
        columns += before.suites
        for suite in before.suites:
            keys = sorted(before.episodes(CLEAN, suite), key=str)
            tsr_before = per_episode_level_tsr(before, suite, keys)
            tsr_after = per_episode_level_tsr(after, suite, keys)
            for level in (CLEAN, *LEVELS):
                if level not in tsr_before or level not in tsr_after:
                    cells[level].append("-")
                    continue
                (b, n_before), (a, n_after) = tsr_before[level], tsr_after[level]
                if n_before != n_after:  # e.g. a leave-one-out sweep of the held-out attack only
                    cells[level].append("-")
                    continue
                mean, low, high = mean_interval(a - b)
                drop = float((tsr_before[CLEAN][0] - b).mean())
                share = mean / drop if drop > 0 and level != CLEAN else None
                cell = pp_cell(mean, low, high)
                if level != CLEAN:
                    cell += f" of {100 * drop:.1f}" + (f" ({100 * share:.0f}%)" if share is not None else "")
                    cell += attack_count(n_before)
                cells[level].append(cell)
                records.append(
                    {"before": before.label, "after": after.label, "suite": suite, "level": level}
                    | {"attacks": n_before, "episodes": len(keys), "tsr_before": float(b.mean())}
                    | {"tsr_after": float(a.mean()), "change": mean, "ci_low": low, "ci_high": high}
                    | {"drop_before": None if level == CLEAN else drop, "share_recovered": share}
                )
    compared = "; ".join(f"before = {b.label}, after = {a.label}" for b, a in pairs)
    table = Table(
        groups, columns, level_rows(cells), corner="Level", notes=(CHANGE_NOTE, compared), unit="pp"
    )
    return table, records
