"""What the laser blinding fits gain from keeping decoded features between the columns of a finite-difference
Jacobian (``BlindingFrames.decode_memo``). Every figure measured in this one run:

    python scripts/bench_calibration.py [--pairs DIR] [--out outputs/bench_calibration.json]

A finite-difference Jacobian moves one parameter at a time, and only the tone curve's parameters change what a
frame's stored values decode to; before the memo every column decoded the scene, the laser capture and its dark
level again (the meter's probe pixels too), and the decode's powers took most of a colour-correcting blinding
calibration's CPU time. Each model below is fitted on every pair twice, with the decodes kept and with none kept
(a memo of size 0), alternating which goes first, ``--repeats`` times; the least process CPU time of each, the
ratio, and whether the two fits' parameters agree exactly (they must: the memo returns what the decode computes).

Pairs: ``--pairs`` (a frame-pairs folder ``lerobot-phantom-calibrate --attack laser_blinding`` reads, resized as the
CLI does), or by default pairs rendered here: smooth scenes lit by a red laser spot whose light adds in linear
light and clips, stored through sRGB, the spot captured alone through an attenuator. One thread (as the CLI fits).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import draccus
import numpy as np
import torch
from threadpoolctl import threadpool_limits

from lerobot_phantom.calibration.cli import CalibrateConfig
from lerobot_phantom.calibration.frame_models.common import Pair, ParameterMemo, load_pairs
from lerobot_phantom.calibration.frame_models.laser_blinding import BlindingFrames
from lerobot_phantom.transforms import physics

MODELS = (
    ("linear_light_saturation", "tone_shoulder"),
    ("linear_light_saturation", "auto_exposure", "tone_shoulder", "halo_power_law"),
    ("linear_light_saturation", "auto_exposure", "tone_shoulder", "colour_correction"),
)


@dataclass
class CalibrationBenchConfig:
    out: Path = Path("outputs/bench_calibration.json")
    # frame pairs to fit; None: render them here
    pairs: Path | None = None
    seed: int = 0
    # fits of each model per variant; the least CPU time is reported
    repeats: int = 3
    # models, each a set of laser blinding effects joined by "+"
    models: list[str] = field(default_factory=lambda: ["+".join(m) for m in MODELS])


def rendered_pairs(seed: int, count: int = 8, height: int = 96, width: int = 128) -> list[Pair]:
    """Smooth scenes plus a red laser spot (Gaussian core, power-law glare) added in linear light and clipped,
    stored through sRGB; the spot's capture alone at a thirtieth of the power."""
    rng = np.random.default_rng(seed)
    ys, xs = np.mgrid[0:height, 0:width].astype(float)
    colour = np.array([1.0, 0.08, 0.05])
    pairs = []
    for i in range(count):
        scene = sum(
            rng.uniform(0.1, 0.5, 3)[:, None, None]
            * np.exp(
                -((xs - rng.uniform(0, width)) ** 2 + (ys - rng.uniform(0, height)) ** 2)
                / rng.uniform(200, 900)
            )
            for _ in range(4)
        ) + rng.uniform(0.05, 0.15)
        cx, cy = rng.uniform(0.3, 0.7) * width, rng.uniform(0.3, 0.7) * height
        r = np.hypot(xs - cx, ys - cy)
        spot = np.exp(-(r**2) / (2 * 6.0**2)) + 0.02 * (1 + r / 2.0) ** -1.8
        intensity = rng.uniform(0.3, 1.0)
        light = 30.0 * intensity * spot[None] * colour[:, None, None]
        attacked = physics.encode(torch.from_numpy(np.clip(scene + light, 0.0, 1.0)), None)
        capture = physics.encode(torch.from_numpy(np.clip(light / (30.0 * intensity), 0.0, 1.0)), None)
        clean = physics.encode(torch.from_numpy(np.clip(scene, 0.0, 1.0)), None)
        stored = [torch.round(v * 255.0) / 255.0 for v in (clean, attacked, capture)]
        pairs.append(Pair(f"pair{i}", *stored, float(intensity), original_size=(width, height)))
    return pairs


def timed_fit(problem: BlindingFrames, effects: frozenset[str], items: np.ndarray) -> tuple[float, dict]:
    """(process CPU seconds, fitted parameters) of one fit of ``effects`` on ``items``."""
    began = time.process_time()
    params = problem.fit(effects, items).params
    return time.process_time() - began, params


def main(cfg: CalibrationBenchConfig) -> dict:
    pairs = (
        load_pairs(cfg.pairs, max_side=CalibrateConfig().max_side) if cfg.pairs else rendered_pairs(cfg.seed)
    )
    results = []
    with threadpool_limits(1):
        torch.set_num_threads(1)
        for k, model in enumerate(cfg.models):
            effects = frozenset(model.split("+"))
            kept, fresh = BlindingFrames(pairs, cfg.seed), BlindingFrames(pairs, cfg.seed)
            fresh.decode_memo = ParameterMemo(0)
            items = np.arange(kept.n_items)
            order = [("kept", kept), ("not kept", fresh)]
            timed = {}
            for _ in range(cfg.repeats):
                for name, problem in order if k % 2 == 0 else order[::-1]:
                    seconds, params = timed_fit(problem, effects, items)
                    best = timed.get(name, (float("inf"), params))[0]
                    timed[name] = (min(best, seconds), params)
            row = {
                "model": sorted(effects),
                "cpu_s_decodes_kept": round(timed["kept"][0], 2),
                "cpu_s_none_kept": round(timed["not kept"][0], 2),
                "ratio": round(timed["not kept"][0] / timed["kept"][0], 2),
                "same_parameters": timed["kept"][1] == timed["not kept"][1],
            }
            print(json.dumps(row), flush=True)
            results.append(row)
    report = {"pairs": str(cfg.pairs) if cfg.pairs else f"rendered, seed {cfg.seed}", "fits": results}
    cfg.out.parent.mkdir(parents=True, exist_ok=True)
    cfg.out.write_text(json.dumps(report, indent=1))
    return report


if __name__ == "__main__":
    main(draccus.parse(CalibrationBenchConfig))
