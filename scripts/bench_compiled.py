"""Would ``torch.compile`` (inductor's CPU C++ backend) fuse the attacks' kernels past the speed targets? Every figure
measured in this one run:

    nice -n 0 python scripts/bench_compiled.py [--out outputs/bench_compiled.json]

For the attacks that miss their targets in ``scripts/bench_transforms.py`` (224x224, batch 32, one thread), the
paper's formula written as one fused pointwise graph (the best formulation found for each; several are printed where
the formulation decides), compiled with ``torch.compile``, against the package's own kernel on the same batch and
parameters:

* the first call's wall time: the process's first compile (dynamo and inductor set-up, inductor's CPU ISA check,
  which builds and loads test libraries in subprocesses that each import torch, then gcc), then each further graph;
* the steady-state throughput of the package's kernel and of the compiled one, as a ratio to ``torch.clone`` of the
  same batch (best process-CPU time of repeated calls, the clone timed before and after, the faster used);
* how the compiled output compares with the package's (uint8: share of values off, largest difference in grey
  levels; float: largest absolute difference);
* recompilation: the first call of one graph at new batch sizes (``dynamic=False`` and ``True``) and at new values
  of a Python-float parameter;
* dataloader workers (2 workers, ``fork`` and ``spawn``): the first and second call of a compiled graph in each
  worker, the parent having called it (fork) or not (fork, spawn).

Nothing here is used by the package: the measured result is why (README, Performance). Writes JSON to ``--out``.
"""

import json
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import torch.utils.data

# one compile thread: inductor would otherwise start a pool of compile workers on a shared machine
os.environ.setdefault("TORCHINDUCTOR_COMPILE_THREADS", "1")
os.environ.setdefault("HF_HUB_OFFLINE", "1")

import draccus
import torch
import torch.nn.functional as nnf

from lerobot_phantom.transforms import em_color_strip as ecs
from lerobot_phantom.transforms import light_projection as lp
from lerobot_phantom.transforms.laser_color_strip import _band_gain, band_rows
from lerobot_phantom.transforms.registry import make_attack


@dataclass
class CompiledBenchConfig:
    out: Path = Path("outputs/bench_compiled.json")
    size: int = 224
    batch: int = 32
    calls: int = 40
    # the recompilation and dataloader-worker measurements (a few minutes: every fresh process compiles)
    processes: bool = True


# -- the fused graphs ------------------------------------------------------------------------------------------


def laser_blinding_level(x, offset, keep):
    """A level: ``x (1 - alpha) + (alpha p 255 + 0.5)``, one fused multiply-add as the package's ``torch.add``."""
    return torch.ops.prims.fma(x.to(torch.float32), keep, offset).to(torch.uint8)


def laser_blinding_lerp(x, grey, weight):
    """Per-sample weights: the package's ``lerp`` and rounding, fused."""
    return torch.lerp(x.to(torch.float32), grey, weight).add(0.5).to(torch.uint8)


def laser_blinding_two_fma(x, grey, weight):
    """Per-sample weights, cheaper: ``x (1 - w) + (p w + 0.5)`` (not ``lerp``'s formula)."""
    return torch.ops.prims.fma(x.to(torch.float32), 1.0 - weight, grey * weight + 0.5).to(torch.uint8)


def light_projection_window(x, alpha8, colour, transparency, rows: slice, cols: slice):
    """The package's integer composite (PIL's ``paste`` formula) under the watermark, the rest copied."""
    m = torch.floor(alpha8 * transparency + lp._ALPHA_EPS).to(torch.int16)
    v = x[:, :, rows, cols].to(torch.int16) * (255 - m) + (colour * m + 128)
    v = (v + ((v >> 8) & 255)) >> 8
    out = x.clone()
    out[:, :, rows, cols] = v.to(torch.uint8)
    return out


def laser_color_strip_float_math(x, gain, profile):
    """``min(x + round(S f I), 255)`` over the frame (``profile`` zero outside the band), in float32."""
    increment = (gain[:, :, None, None] * profile).round()
    return (x.to(torch.float32) + increment).clamp(max=255.0).to(torch.uint8)


def em_color_strip_uint8_math(x, rows):
    """The paper's integer formula in uint8 ops, corrupted rows selected per sample and row (``rows`` (B,1,H,1))."""
    r, g, b = x[:, 0:1], x[:, 1:2], x[:, 2:3]
    new_g = ((r & b) + ((r ^ b) >> 1)).clamp(min=50) - 50
    capped = g.clamp(max=102)
    new_rb = capped * 2 + (capped >> 1)
    channel = torch.arange(3, device=x.device)[None, :, None, None]
    return torch.where(rows, torch.where(channel == 1, new_g, new_rb), x)


def em_color_strip_float_math(x, rows):
    """The same integer formula computed in float32 (exact on 0..510), one conversion each way."""
    y = x.to(torch.float32)
    r, g, b = y[:, 0:1], y[:, 1:2], y[:, 2:3]
    new_g = (torch.floor((r + b) * 0.5) - 50.0).clamp(min=0.0)
    new_rb = torch.floor(g * 2.5).clamp(max=255.0)
    channel = torch.arange(3, device=x.device)[None, :, None, None]
    return torch.where(rows, torch.where(channel == 1, new_g, new_rb), y).to(torch.uint8)


def em_color_strip_float(x, rows):
    """Float images: the package's continuous formula, clamped."""
    y = x.clamp(0.0, 1.0)
    r, g, b = y[:, 0:1], y[:, 1:2], y[:, 2:3]
    new_rb = g * ecs.GREEN_GAIN
    new_g = torch.lerp(r, b, 0.5) - ecs.GREEN_OFFSET
    channel = torch.arange(3, device=x.device)[None, :, None, None]
    return torch.where(rows, torch.where(channel == 1, new_g, new_rb).clamp(0.0, 1.0), y)


def ultrasound_blur_box(x, length: int):
    """The diagonal path of ``length`` samples (the paper's levels): zero-pad, sum shifted views, divide by the
    in-bounds count; uint8 rounds half to even as the package."""
    height, width = x.shape[-2:]
    wide = nnf.pad(x.to(torch.int16 if x.dtype == torch.uint8 else x.dtype), (0, length - 1, 0, length - 1))
    total = wide[:, :, :height, :width]
    for i in range(1, length):
        total = total + wide[:, :, i : i + height, i : i + width]
    r = torch.arange(height, device=x.device)[:, None]
    c = torch.arange(width, device=x.device)[None, :]
    count = torch.clamp(torch.minimum(height - r, width - c), max=length).to(torch.float32)
    mean = total.to(torch.float32) / count
    return mean.round().to(torch.uint8) if x.dtype == torch.uint8 else mean


# -- arguments of each graph from the package's parameters ----------------------------------------------------


def _laser_level(attack, params, x):
    grey = attack.patterns_for(params["position"], *x.shape[-2:], x.device) * 255.0
    alpha = float(params["alpha"][0])
    return (x, torch.mul(grey[0], alpha).add_(0.5), 1.0 - alpha)


def _laser_weights(attack, params, x):
    grey = attack.patterns_for(params["position"], *x.shape[-2:], x.device) * 255.0
    return (x, grey, params["alpha"].reshape(-1, 1, 1, 1).to(torch.float32))


def _projection(attack, params, x):
    height, width = x.shape[-2:]
    rgba = attack.watermark(height, width, x.device)
    offsets = params["offset"]
    if not bool((offsets == 0).all()):
        raise ValueError("the benchmark's light projection graph places the watermark at the centre only")
    top, left = (height - rgba.shape[-2]) // 2, (width - rgba.shape[-1]) // 2
    (rows, cols), alpha8, colour = lp._integer_window(rgba, top, left, height, width)
    return (x, alpha8, colour, params["transparency"].reshape(-1, 1, 1, 1).to(torch.float32), rows, cols)


def _strip(attack, params, x):
    height, width = x.shape[-2:]
    start, end = band_rows(height)
    profile = torch.zeros(height, width)
    profile[start:end] = attack.profile(height, width, x.device)
    gain = _band_gain(params["strength"], params["color_fractions"], x.device)
    return (x, gain.expand(x.shape[0], 3).contiguous(), profile)


def _stripe_rows(attack, params, x):
    weights = ecs.row_weights_of(x, params)
    if not bool(((weights == 0) | (weights == 1)).all()):
        raise ValueError("the benchmark's EM color strip graph covers whole-row patterns (levels, 'random')")
    return (x, (weights > 0)[:, None, :, None])


def _blur(attack, params, x):
    d = params["dx"]
    if not bool(((d == d[0]) & (params["dy"] == d[0])).all()):
        raise ValueError("the benchmark's blur graph takes one diagonal displacement for the batch")
    return (x, int(float(d[0])) + 1)


CASES: list[tuple[str, str, str, Callable, Callable]] = [
    # (attack, intensity, dtype, graph, its arguments)
    ("laser_blinding", "strong", "uint8", laser_blinding_level, _laser_level),
    ("laser_blinding", "random", "uint8", laser_blinding_lerp, _laser_weights),
    ("laser_blinding", "random", "uint8", laser_blinding_two_fma, _laser_weights),
    ("light_projection", "random", "uint8", light_projection_window, _projection),
    ("laser_color_strip", "strong", "uint8", laser_color_strip_float_math, _strip),
    ("laser_color_strip", "random", "uint8", laser_color_strip_float_math, _strip),
    ("em_color_strip", "strong", "uint8", em_color_strip_uint8_math, _stripe_rows),
    ("em_color_strip", "strong", "uint8", em_color_strip_float_math, _stripe_rows),
    ("em_color_strip", "random", "uint8", em_color_strip_float_math, _stripe_rows),
    ("em_color_strip", "strong", "float32", em_color_strip_float, _stripe_rows),
    ("em_color_strip", "random", "float32", em_color_strip_float, _stripe_rows),
    ("ultrasound_blur", "strong", "uint8", ultrasound_blur_box, _blur),
    ("ultrasound_blur", "strong", "float32", ultrasound_blur_box, _blur),
]


# -- recompilation and dataloader workers --------------------------------------------------------------------


def _worker_graph(x, grey, weight):
    """``laser_blinding_two_fma`` as a code object of its own: dynamo caches compiled graphs per code object, and
    the worker measurement must not find the one the parent compiled earlier."""
    return torch.ops.prims.fma(x.to(torch.float32), 1.0 - weight, grey * weight + 0.5).to(torch.uint8)


WORKER_GRAPH = torch.compile(_worker_graph)
"""Compiled lazily in whichever process calls it first (a spawned worker re-imports this module)."""


def _worker_args(size: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    generator = torch.Generator().manual_seed(2)
    x = torch.randint(0, 256, (4, 3, size, size), dtype=torch.uint8, generator=generator)
    return (
        x,
        torch.rand(1, 3, size, size, generator=generator) * 255,
        torch.rand(4, 1, 1, 1, generator=generator),
    )


class FirstCalls(torch.utils.data.Dataset):
    """Each item: (worker pid, first call s, second call s) of ``WORKER_GRAPH`` in the worker that loads it."""

    def __init__(self, size: int) -> None:
        self.size = size

    def __len__(self) -> int:
        return 2

    def __getitem__(self, index: int) -> torch.Tensor:
        torch.set_num_threads(1)
        args = _worker_args(self.size)
        times = []
        for _ in range(2):
            started = time.perf_counter()
            WORKER_GRAPH(*args)
            times.append(time.perf_counter() - started)
        return torch.tensor([os.getpid(), *times], dtype=torch.float64)


def worker_first_calls(size: int) -> list[dict]:
    rows = []
    for context, parent_called in (("fork", False), ("spawn", False), ("fork", True)):
        if parent_called:
            WORKER_GRAPH(*_worker_args(size))
        loader = torch.utils.data.DataLoader(
            FirstCalls(size), batch_size=None, num_workers=2, multiprocessing_context=context
        )
        for pid, first, second in (item.tolist() for item in loader):
            rows.append(
                {
                    "context": context,
                    "parent_called": parent_called,
                    "pid": int(pid),
                    "first_call_s": first,
                    "second_call_s": second,
                }
            )
    return rows


def recompilations(size: int) -> list[dict]:
    """First-call seconds of a graph at successive batch sizes, and of a level graph at successive alphas."""
    rows = []
    grey = torch.rand(1, 3, size, size) * 255
    for dynamic in (False, True):
        graph = torch.compile(laser_blinding_two_fma, dynamic=dynamic)
        for batch in (32, 8, 1, 16, 32):
            x = torch.zeros(batch, 3, size, size, dtype=torch.uint8)
            started = time.perf_counter()
            graph(x, grey, torch.rand(batch, 1, 1, 1))
            rows.append({"dynamic": dynamic, "batch": batch, "first_call_s": time.perf_counter() - started})
        level = torch.compile(laser_blinding_level, dynamic=dynamic)
        x = torch.zeros(32, 3, size, size, dtype=torch.uint8)
        for alpha in (0.1, 0.5, 0.9, 0.1):
            started = time.perf_counter()
            level(x, grey[0] * alpha + 0.5, 1.0 - alpha)
            rows.append({"dynamic": dynamic, "alpha": alpha, "first_call_s": time.perf_counter() - started})
    return rows


# -- the run ------------------------------------------------------------------------------------------------


def _best(fn: Callable[[], object], calls: int) -> float:
    """Best process-CPU seconds of ``calls`` calls after one warm-up (one thread: see bench_transforms)."""
    fn()
    best = float("inf")
    for _ in range(calls):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def _batch(batch: int, size: int, dtype: str) -> torch.Tensor:
    images = torch.randint(
        0, 256, (batch, 3, size, size), dtype=torch.uint8, generator=torch.Generator().manual_seed(0)
    )
    return images if dtype == "uint8" else images.to(torch.float32) / 255


def _compare(out: torch.Tensor, ref: torch.Tensor) -> dict[str, float]:
    if out.dtype == torch.uint8:
        diff = out.to(torch.int16) - ref.to(torch.int16)
        return {"share_off": float((diff != 0).double().mean()), "max_off": float(diff.abs().max())}
    diff = (out - ref).abs()
    return {"share_off": float((diff > 1e-6).double().mean()), "max_off": float(diff.max())}


def run(cfg: CompiledBenchConfig) -> dict:
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        started = time.perf_counter()
        torch.compile(lambda t: t + 1)(torch.zeros(4))
        process_first_compile_s = time.perf_counter() - started
        rows = []
        for name, intensity, dtype, graph, arguments in CASES:
            x = _batch(cfg.batch, cfg.size, dtype)
            attack = make_attack(name, intensity=intensity, seed=0)
            params = attack.sample_params(
                cfg.batch, cfg.size, cfg.size, generator=torch.Generator().manual_seed(1)
            )
            reference = attack.apply_params(x, params)
            args = arguments(attack, params, x)
            compiled = torch.compile(graph)
            started = time.perf_counter()
            out = compiled(*args)
            first_call_s = time.perf_counter() - started
            clone_s = _best(x.clone, cfg.calls)
            package_s = _best(lambda a=attack, p=params, x=x: a.apply_params(x, p), cfg.calls)
            compiled_s = _best(lambda f=compiled, a=args: f(*a), cfg.calls)
            clone_s = min(clone_s, _best(x.clone, cfg.calls))
            rows.append(
                {
                    "attack": name,
                    "intensity": intensity,
                    "dtype": dtype,
                    "graph": graph.__name__,
                    "first_call_s": first_call_s,
                    "package_clone_ratio": clone_s / package_s,
                    "compiled_clone_ratio": clone_s / compiled_s,
                    **_compare(out, reference),
                }
            )
        recompiled = recompilations(cfg.size) if cfg.processes else []
        workers = worker_first_calls(cfg.size) if cfg.processes else []
    finally:
        torch.set_num_threads(threads)
    return {
        "meta": {
            "torch": torch.__version__,
            "size": cfg.size,
            "batch": cfg.batch,
            "threads": 1,
            "TORCHINDUCTOR_VEC_ISA_OK": os.environ.get("TORCHINDUCTOR_VEC_ISA_OK"),
            "load_average": os.getloadavg(),
            "time": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        },
        "process_first_compile_s": process_first_compile_s,
        "results": rows,
        "recompilations": recompiled,
        "workers": workers,
    }


def report(result: dict) -> str:
    meta = result["meta"]
    lines = [
        f"{meta['size']}x{meta['size']}, batch {meta['batch']}, 1 thread, torch {meta['torch']}; the process's "
        f"first torch.compile call (a one-op graph): {result['process_first_compile_s']:.1f} s "
        f"(TORCHINDUCTOR_VEC_ISA_OK={meta['TORCHINDUCTOR_VEC_ISA_OK']})",
        "",
        "| attack | intensity | dtype | graph | first call s | package × clone | compiled × clone | off (share, max) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in result["results"]:
        off = f"{r['share_off']:.2%}, {r['max_off']:.3g}"
        lines.append(
            f"| {r['attack']} | {r['intensity']} | {r['dtype']} | {r['graph']} | {r['first_call_s']:.1f} "
            f"| {r['package_clone_ratio']:.3f} | {r['compiled_clone_ratio']:.3f} | {off} |"
        )
    for dynamic in (False, True):
        mine = [r for r in result["recompilations"] if r["dynamic"] is dynamic]
        if mine:
            lines.append(
                f"dynamic={dynamic}: first call s at batch "
                + ", ".join(f"{r['batch']} {r['first_call_s']:.2f}" for r in mine if "batch" in r)
                + "; level graph at alpha "
                + ", ".join(f"{r['alpha']} {r['first_call_s']:.2f}" for r in mine if "alpha" in r)
            )
    for r in result["workers"]:
        lines.append(
            f"{r['context']} worker {r['pid']} (parent {'called' if r['parent_called'] else 'did not call'} the "
            f"graph): first call {r['first_call_s']:.3f} s, second {1000 * r['second_call_s']:.2f} ms"
        )
    lines.append(f"load average {tuple(round(v, 2) for v in meta['load_average'])}")
    return "\n".join(lines)


@draccus.wrap()
def main(cfg: CompiledBenchConfig) -> None:
    result = run(cfg)
    cfg.out.parent.mkdir(parents=True, exist_ok=True)
    cfg.out.write_text(json.dumps(result, indent=2))
    print(report(result))
    print(f"wrote {cfg.out}")


if __name__ == "__main__":
    main()
