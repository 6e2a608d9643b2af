"""Seconds per training step of lerobot-phantom-train: rate 0 vs 0.3, dataloader vs device attacks, in one run.

Builds a small dataset and a weightless SmolVLA backbone in a temporary directory (offline), runs LeRobot's loop
through ``train_phantom`` for each setting, and times the gap between consecutive optimizer steps (data loading +
preprocessing + attacks + forward/backward), median over the steps after a warm-up, in CPU time of this process
(robust to other jobs on a shared machine) and wall time. Each setting runs once per round, rounds alternate the
order, the best round is kept. Separately, ``data_cpu_s_per_batch`` times reading, attacking and labelling one
batch without a model, so the attack's own cost (rate 0.3 minus rate 0) can be set against any step time. Prints the
ratios and writes them as JSON.

    python scripts/bench_train.py [--steps 30] [--warmup 5] [--batch-size 8] [--image-size 96] [--out FILE]

The target is that ``--phantom.rate=0.3`` costs <= 5 % step time. Note the policy here is a CPU toy, so an attack's
share of a step is far larger than next to a real VLA on a GPU; the ratio is an upper bound for that setting.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import tempfile
import time
from pathlib import Path

os.environ.setdefault("HF_HUB_OFFLINE", "1")

SETTINGS = (
    ("rate0_dataloader", 0.0, "dataloader"),
    ("rate0.3_dataloader", 0.3, "dataloader"),
    ("rate0_device", 0.0, "device"),
    ("rate0.3_device", 0.3, "device"),
)


def time_run(args: list[str], warmup: int) -> dict[str, float]:
    """Median wall and CPU seconds between consecutive optimizer steps (after ``warmup``) of one training run.

    CPU time (``time.process_time``, this process only) is the figure to compare on a shared machine: other jobs
    inflate wall time but not it.
    """
    from lerobot_phantom.train import train as train_module

    stamps: list[tuple[float, float]] = []
    original = train_module._PhantomTrainingRun.update_policy

    def timed(self, *a, **kw):
        stamps.append((time.perf_counter(), time.process_time()))
        return original(self, *a, **kw)

    train_module._PhantomTrainingRun.update_policy = timed
    try:
        train_module.main(args)
    finally:
        train_module._PhantomTrainingRun.update_policy = original
    timed_stamps = stamps[warmup:]
    if len(timed_stamps) < 2:
        raise ValueError(f"need more than warmup + 1 steps to time, got {len(stamps)} steps")
    pairs = list(itertools.pairwise(timed_stamps))
    return {
        "wall_s_per_step": statistics.median(b[0] - a[0] for a, b in pairs),
        "cpu_s_per_step": statistics.median(b[1] - a[1] for a, b in pairs),
        "timed_steps": len(pairs),
    }


def time_batches(root: Path, rate: float, where: str, batch_size: int, batches: int) -> float:
    """Median CPU seconds to read, attack and label one batch (mixer + collate + device step), no model."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset
    from lerobot.processor import PolicyProcessorPipeline
    from torch.utils.data import default_collate

    from lerobot_phantom.config import PhantomConfig
    from lerobot_phantom.datasets import PhantomDataset
    from lerobot_phantom.train.device_step import PhantomAttackProcessorStep, TrainingPreprocessor

    config = PhantomConfig(rate=rate, where=where)
    dataset = PhantomDataset(LeRobotDataset("phantom/tiny", root=root), config, apply=where == "dataloader")
    step = PhantomAttackProcessorStep(phantom=config, camera_keys=list(dataset.camera_keys))
    preprocessor = TrainingPreprocessor(
        PolicyProcessorPipeline(steps=[]), step if where == "device" else None
    )
    times = []
    for b in range(batches):
        start = time.process_time()
        indices = [(b * batch_size + i) % len(dataset) for i in range(batch_size)]
        preprocessor(default_collate([dataset[i] for i in indices]))
        times.append(time.process_time() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30)
    parser.add_argument("--warmup", type=int, default=5)
    parser.add_argument("--batch-size", type=int, default=8)
    parser.add_argument("--image-size", type=int, default=96)
    parser.add_argument("--vlm-size", default="tiny", choices=["tiny", "small"])
    parser.add_argument(
        "--rounds", type=int, default=2, help="each setting runs once per round; best round kept"
    )
    parser.add_argument("--threads", type=int, default=1, help="torch intra-op threads (1: steadier figures)")
    parser.add_argument("--out", type=Path, default=Path("outputs/bench_train.json"))
    opts = parser.parse_args()

    import torch

    torch.set_num_threads(opts.threads)

    from lerobot_phantom.datasets.synthetic import TASKS, build_synthetic_dataset
    from lerobot_phantom.train.make_vlm import VLM_SIZES, make_vlm

    results: dict[str, dict] = {}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        build_synthetic_dataset(
            tmp / "data",
            "phantom/tiny",
            episode_lengths=(24,) * 4,
            size=opts.image_size,
            cameras=("observation.images.front",),
        )
        vlm = make_vlm(tmp / "vlm", opts.vlm_size, tasks=TASKS)
        side = VLM_SIZES[opts.vlm_size]["image_size"]
        # Alternate the order between rounds so a drift in machine load does not favour one setting.
        order = [s for r in range(opts.rounds) for s in (SETTINGS if r % 2 == 0 else SETTINGS[::-1])]
        for round_index, (name, rate, where) in enumerate(order):
            args = [
                "--dataset.repo_id=phantom/tiny",
                f"--dataset.root={tmp / 'data'}",
                "--policy.type=smolvla",
                f"--policy.vlm_model_name={vlm}",
                "--policy.load_vlm_weights=false",
                f"--policy.resize_imgs_with_padding=[{side},{side}]",
                "--policy.chunk_size=4",
                "--policy.n_action_steps=4",
                "--policy.device=cpu",
                "--policy.push_to_hub=false",
                f"--output_dir={tmp / f'{name}_{round_index}'}",
                f"--batch_size={opts.batch_size}",
                f"--steps={opts.steps}",
                "--save_checkpoint=false",
                "--log_freq=0",
                "--num_workers=0",
                "--eval_freq=0",
                "--wandb.enable=false",
                f"--phantom.rate={rate}",
                f"--phantom.where={where}",
            ]
            timing = time_run(args, opts.warmup)
            timing["data_cpu_s_per_batch"] = time_batches(
                tmp / "data", rate, where, opts.batch_size, batches=opts.steps
            )
            best = results.get(name)
            if best is None or timing["cpu_s_per_step"] < best["cpu_s_per_step"]:
                results[name] = {"rate": rate, "where": where, **timing}

    def ratio(a: str, b: str, key: str = "cpu_s_per_step") -> float:
        return results[a][key] / results[b][key]

    for name, record in results.items():
        record["cpu_ratio_to_rate0_dataloader"] = ratio(name, "rate0_dataloader")
        record["wall_ratio_to_rate0_dataloader"] = ratio(name, "rate0_dataloader", "wall_s_per_step")
    summary = {
        "rate0.3_over_rate0_dataloader": ratio("rate0.3_dataloader", "rate0_dataloader"),
        "rate0.3_over_rate0_device": ratio("rate0.3_device", "rate0_device"),
        "device_over_dataloader_at_rate0.3": ratio("rate0.3_device", "rate0.3_dataloader"),
        # Portable figure: the attack's added CPU time per batch as a fraction of this toy policy's step time.
        "attack_overhead_dataloader": (
            results["rate0.3_dataloader"]["data_cpu_s_per_batch"]
            - results["rate0_dataloader"]["data_cpu_s_per_batch"]
        )
        / results["rate0_dataloader"]["cpu_s_per_step"],
        "attack_overhead_device": (
            results["rate0.3_device"]["data_cpu_s_per_batch"]
            - results["rate0_device"]["data_cpu_s_per_batch"]
        )
        / results["rate0_device"]["cpu_s_per_step"],
    }
    report = {
        "config": vars(opts) | {"out": str(opts.out)},
        "policy": f"smolvla with a weightless {opts.vlm_size} VLM, CPU",
        "results": results,
        "summary": summary,
    }
    print(
        f"{'setting':<22}{'cpu s/step':>11}{'ratio':>8}{'wall s/step':>12}{'ratio':>8}{'data cpu s/batch':>18}"
    )
    for name, r in results.items():
        print(
            f"{name:<22}{r['cpu_s_per_step']:>11.4f}{r['cpu_ratio_to_rate0_dataloader']:>8.3f}"
            f"{r['wall_s_per_step']:>12.4f}{r['wall_ratio_to_rate0_dataloader']:>8.3f}"
            f"{r['data_cpu_s_per_batch']:>18.4f}"
        )
    for key, value in summary.items():
        print(f"{key} (cpu time): {value:.3f}")
    opts.out.parent.mkdir(parents=True, exist_ok=True)
    opts.out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {opts.out}")


if __name__ == "__main__":
    main()
