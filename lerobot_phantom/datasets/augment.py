"""``lerobot-phantom-augment``: write an attack-augmented copy of a LeRobot dataset (a new LeRobotDataset v3).

    lerobot-phantom-augment --repo-id SRC --root SRC_DIR --output-repo-id DST --output-root DST_DIR \\
        --phantom.rate 0.3 [--phantom.* ...] [--unit frame|episode] [--resume] [--overwrite] [--num-workers N]

Which frames (``--unit frame``) or whole episodes (``--unit episode``) are attacked, by what and how hard is the
online mixer's epoch-0 schedule (``PhantomDataset``): exact fractions, reproducible from ``--phantom.seed``. With
``--unit episode`` every frame of an attacked episode gets the same attack with the same parameters. Every frame
gains two columns, ``phantom_attack`` (attack name or ``"none"``) and ``phantom_intensity``; with an instruction
channel (``--phantom.instruction_rate``) also ``phantom_instruction_attack``. Attacked instructions become new task
strings in the task table. Image and video datasets alike are decoded, attacked and re-encoded; statistics are
recomputed by LeRobot (per-episode stats when each episode is saved, aggregated when the episodes are merged).
Frame timestamps are LeRobot's ``frame_index / fps`` (``add_frame`` does not take them). The run's settings and
its summary (frames per attack and per nearest intensity level, also printed at the end) are kept in
``meta/phantom_augment.json``.

How it stays safe and resumable:

* the source is only read; the output may not be the source, lie inside it or contain it, and an existing output is
  refused unless ``--overwrite`` (replaced only once the new one is complete) or ``--resume``;
* everything is written under a temporary sibling directory ``.<output name>.phantom-augment-tmp``: each source
  episode becomes a small finalized dataset ``episodes/NNNNNN`` (written as ``NNNNNN.partial`` and renamed when
  finalized, so a kill -9 leaves at most one partial episode), then LeRobot's ``aggregate_datasets`` merges them in
  episode order into ``aggregate`` and that directory is renamed into place;
* ``--resume`` checks that the run's settings match the interrupted run's (``run.json``), drops partial episodes,
  keeps finalized ones and carries on. Each episode's content depends only on the source and the settings, so the
  result is identical to an uninterrupted run's, whatever ``--num-workers``.
"""

from __future__ import annotations

import json
import logging
import os
import shutil
import sys
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import numpy as np
import torch
from tqdm import tqdm

from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom._cli import normalize_argv as normalize_cli_argv
from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.datasets.mixer import PhantomDataset
from lerobot_phantom.transforms.intensity import LEVELS

UNITS = ("frame", "episode")
ATTACK_COLUMN = "phantom_attack"
INTENSITY_COLUMN = "phantom_intensity"
INSTRUCTION_COLUMN = "phantom_instruction_attack"
CLEAN_NAME = "none"
TMP_SUFFIX = ".phantom-augment-tmp"
RUN_FILE = "run.json"
PROVENANCE_FILE = "meta/phantom_augment.json"


@dataclass
class AugmentConfig:
    # Source dataset (read only).
    repo_id: str = ""
    # Local directory of the source (default: $HF_LEROBOT_HOME/<repo_id>).
    root: str | None = None
    # The new dataset.
    output_repo_id: str = ""
    # Where it is written (default: $HF_LEROBOT_HOME/<output_repo_id>).
    output_root: str | None = None
    phantom: PhantomConfig = field(default_factory=PhantomConfig)
    # 'frame': attack individual frames; 'episode': attack whole episodes (same attack and parameters throughout).
    unit: str = "frame"
    # Continue an interrupted run (same settings) instead of refusing its leftovers.
    resume: bool = False
    # Replace an existing output (only once the new one is complete).
    overwrite: bool = False
    # Processes writing episodes in parallel (0: in this process).
    num_workers: int = 0
    # Video codec of re-encoded video features (LeRobot's choices: libsvtav1, h264, hevc, ...).
    vcodec: str = "libsvtav1"

    def __post_init__(self) -> None:
        if self.unit not in UNITS:
            raise ValueError(f"--unit must be one of {UNITS}, got {self.unit!r}")
        if not isinstance(self.num_workers, int) or self.num_workers < 0:
            raise ValueError(f"--num-workers must be an integer >= 0, got {self.num_workers!r}")

    def check_required(self) -> None:
        missing = [name for name in ("repo_id", "output_repo_id") if not getattr(self, name)]
        if missing:
            raise ValueError(
                f"lerobot-phantom-augment needs {', '.join('--' + m.replace('_', '-') for m in missing)}"
            )


@dataclass
class AugmentResult:
    output_root: Path
    num_episodes: int
    num_frames: int
    episodes_reused: int
    summary: dict[str, Any]


# -- paths ---------------------------------------------------------------------------------------------------------
def _dataset_root(repo_id: str, root: str | None) -> Path:
    return (Path(root) if root else Path(compat.lerobot_home()) / repo_id).expanduser().resolve()


def temporary_dir(output_root: Path) -> Path:
    return output_root.parent / f".{output_root.name}{TMP_SUFFIX}"


def _check_not_overlapping(source: Path, output: Path) -> None:
    if output == source:
        raise ValueError(
            f"the output {output} is the source dataset; lerobot-phantom-augment never writes over it"
        )
    if source in output.parents:
        raise ValueError(f"the output {output} lies inside the source dataset {source}; choose another place")
    if output in source.parents:
        raise ValueError(f"the output {output} contains the source dataset {source}; choose another place")


# -- episode jobs --------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _EpisodeJob:
    position: int  # rank of the episode in the source (0..E-1): the schedule's index with --unit episode
    episode_index: int
    start: int  # absolute frame indices [start, stop)
    stop: int
    staging_root: str
    repo_id: str


@dataclass(frozen=True)
class _Plan:
    source_repo_id: str
    source_root: str
    phantom: PhantomConfig
    unit: str
    features: dict
    fps: int
    robot_type: str | None
    use_videos: bool
    vcodec: str
    parallel_encoding: bool


class _Count:
    """A sized stand-in for the source when the schedule runs over episodes instead of frames."""

    def __init__(self, size: int) -> None:
        self.size = size

    def __len__(self) -> int:
        return self.size

    def __getitem__(self, index: int) -> dict:
        raise TypeError("_Count only sizes an episode-level schedule")


_worker_state: dict[str, Any] = {}


def _open(plan: _Plan) -> tuple[Any, PhantomDataset]:
    """The source dataset and the mixer giving each item's decision (cached per process)."""
    key = (plan.source_repo_id, plan.source_root, plan.unit, repr(plan.phantom))
    if _worker_state.get("key") != key:
        from lerobot.datasets.lerobot_dataset import LeRobotDataset

        source = LeRobotDataset(plan.source_repo_id, root=plan.source_root)
        items = source if plan.unit == "frame" else _Count(source.meta.total_episodes)
        mixer = PhantomDataset(items, plan.phantom, camera_keys=list(source.meta.camera_keys))
        _worker_state.update(key=key, source=source, mixer=mixer)
    return _worker_state["source"], _worker_state["mixer"]


def _to_frame_value(value: Any, feature: dict) -> Any:
    if feature["dtype"] in ("image", "video"):
        # Frames arrive as float CHW in [0, 1]; LeRobot's writer truncates floats, so hand it exact uint8 HWC.
        image = value if value.dtype == torch.uint8 else (value.clamp(0, 1) * 255.0).round().to(torch.uint8)
        return image.permute(1, 2, 0).contiguous().numpy()
    if isinstance(value, torch.Tensor):
        array = value.numpy()
        return array.reshape(feature["shape"]) if array.ndim == 0 else array
    return value


def _write_episode(plan: _Plan, job: _EpisodeJob) -> int:
    """Attack one source episode and write it as a finalized single-episode dataset; returns its frame count."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    source, mixer = _open(plan)
    partial = Path(job.staging_root).with_name(Path(job.staging_root).name + ".partial")
    if partial.exists():
        shutil.rmtree(partial)
    writer = LeRobotDataset.create(
        repo_id=job.repo_id,
        fps=plan.fps,
        features=plan.features,
        root=partial,
        robot_type=plan.robot_type,
        use_videos=plan.use_videos,
        vcodec=plan.vcodec,
    )
    episode_choice = mixer.decision(job.position) if plan.unit == "episode" else None
    with_instruction = INSTRUCTION_COLUMN in plan.features
    for index in range(job.start, job.stop):
        item = source[index]
        choice = episode_choice if episode_choice is not None else mixer.decision(index)
        mixer.attack_item(item, choice)
        frame = {
            key: _to_frame_value(item[key], feature)
            for key, feature in plan.features.items()
            if key not in (ATTACK_COLUMN, INTENSITY_COLUMN, INSTRUCTION_COLUMN)
        }
        frame["task"] = item["task"]
        frame[ATTACK_COLUMN] = choice["attack"] or CLEAN_NAME
        frame[INTENSITY_COLUMN] = np.array([choice["intensity"]], dtype=np.float32)
        if with_instruction:
            frame[INSTRUCTION_COLUMN] = choice["instruction_attack"] or CLEAN_NAME
        writer.add_frame(frame)
    writer.save_episode(parallel_encoding=plan.parallel_encoding)
    writer.finalize()
    os.replace(partial, job.staging_root)  # the episode exists only once it is complete
    return job.stop - job.start


def _write_episode_with_context(plan: _Plan, job: _EpisodeJob) -> int:
    try:
        return _write_episode(plan, job)
    except Exception as err:
        err.add_note(
            f"lerobot-phantom-augment: while writing source episode {job.episode_index} "
            f"(frames {job.start}..{job.stop - 1}) of {plan.source_repo_id} to {job.staging_root}.partial"
        )
        raise


def _write_episode_in_worker(plan: _Plan, job: _EpisodeJob) -> int:
    logging.getLogger().setLevel(logging.WARNING)
    return _write_episode_with_context(plan, job)


# -- summary -------------------------------------------------------------------------------------------------------
def _nearest_level(s: float) -> str:
    return min(LEVELS, key=lambda name: abs(LEVELS[name] - s))


def summarize(root: Path) -> dict[str, Any]:
    """Frames per attack (and per nearest intensity level) in a written dataset, read back from its parquet files."""
    import pyarrow.parquet as pq

    names: list[str] = []
    intensities: list[float] = []
    instructions: list[str] = []
    for path in sorted((root / "data").rglob("*.parquet")):
        columns = pq.read_schema(path).names
        wanted = [c for c in (ATTACK_COLUMN, INTENSITY_COLUMN, INSTRUCTION_COLUMN) if c in columns]
        table = pq.read_table(path, columns=wanted).to_pydict()
        names += table[ATTACK_COLUMN]
        intensities += [float(np.asarray(v).reshape(-1)[0]) for v in table[INTENSITY_COLUMN]]
        instructions += table.get(INSTRUCTION_COLUMN, [])
    total = len(names)
    attacks: dict[str, Any] = {}
    for name in sorted(set(names)):
        values = [s for n, s in zip(names, intensities, strict=True) if n == name]
        entry: dict[str, Any] = {"frames": len(values), "fraction": len(values) / total if total else 0.0}
        if name != CLEAN_NAME:
            entry |= {
                "intensity_min": min(values),
                "intensity_mean": sum(values) / len(values),
                "intensity_max": max(values),
                "by_level": {level: sum(_nearest_level(s) == level for s in values) for level in LEVELS},
            }
        attacks[name] = entry
    attacked = total - attacks.get(CLEAN_NAME, {"frames": 0})["frames"]
    summary: dict[str, Any] = {
        "frames": total,
        "attacked_frames": attacked,
        "attacked_fraction": attacked / total if total else 0.0,
        "attacks": attacks,
    }
    if instructions:
        summary["instruction_attacks"] = {
            name: instructions.count(name) for name in sorted(set(instructions))
        }
    return summary


def format_summary(summary: dict[str, Any]) -> str:
    lines = [
        f"{summary['frames']} frames, {summary['attacked_frames']} attacked "
        f"({100 * summary['attacked_fraction']:.2f}%)",
        f"{'attack':<20} {'frames':>8} {'share':>7} {'s mean':>7} {'weak':>6} {'medium':>7} {'strong':>7}",
    ]
    for name, entry in summary["attacks"].items():
        levels = entry.get("by_level", {})
        mean = f"{entry['intensity_mean']:.3f}" if "intensity_mean" in entry else "-"
        lines.append(
            f"{name:<20} {entry['frames']:>8} {100 * entry['fraction']:>6.2f}% {mean:>7} "
            f"{levels.get('weak', '-'):>6} {levels.get('medium', '-'):>7} {levels.get('strong', '-'):>7}"
        )
    for name, count in summary.get("instruction_attacks", {}).items():
        lines.append(f"instruction {name:<12} {count:>8}")
    return "\n".join(lines)


# -- the tool ------------------------------------------------------------------------------------------------------
def _output_features(source_meta: Any, phantom: PhantomConfig) -> dict:
    default_keys = compat.default_feature_keys()
    features = {
        key: {k: v for k, v in feature.items() if k != "info"}  # video info is rewritten by the encoder
        for key, feature in source_meta.features.items()
        if key not in default_keys
    }
    clash = [key for key in (ATTACK_COLUMN, INTENSITY_COLUMN, INSTRUCTION_COLUMN) if key in features]
    if clash:
        raise ValueError(
            f"the source already has {clash}: it looks augmented already; augment the clean source"
        )
    features[ATTACK_COLUMN] = {"dtype": "string", "shape": (1,), "names": None}
    features[INTENSITY_COLUMN] = {"dtype": "float32", "shape": (1,), "names": None}
    if phantom.instruction_attacks and phantom.instruction_rate > 0:
        features[INSTRUCTION_COLUMN] = {"dtype": "string", "shape": (1,), "names": None}
    return features


def _run_record(cfg: AugmentConfig, source_root: Path, source_meta: Any) -> dict[str, Any]:
    """What must match for --resume to continue a run (anything that changes the bytes written)."""
    return {
        "source_root": str(source_root),
        "source_repo_id": cfg.repo_id,
        "source_total_frames": int(source_meta.total_frames),
        "source_total_episodes": int(source_meta.total_episodes),
        "output_repo_id": cfg.output_repo_id,
        "phantom": asdict(cfg.phantom),
        "unit": cfg.unit,
        "vcodec": cfg.vcodec,
    }


def _prepare_tmp(cfg: AugmentConfig, tmp: Path, record: dict[str, Any]) -> None:
    run_file = tmp / RUN_FILE
    if tmp.exists() and cfg.resume and run_file.exists():
        previous = json.loads(run_file.read_text())
        changed = sorted(k for k in set(previous) | set(record) if previous.get(k) != record.get(k))
        if changed:
            raise ValueError(
                f"--resume: the interrupted run in {tmp} used other settings ({', '.join(changed)}); "
                f"rerun with the same settings, or pass --overwrite without --resume to start over"
            )
        return
    if tmp.exists():
        if not (cfg.overwrite or cfg.resume):
            raise FileExistsError(
                f"{tmp} holds an interrupted run; pass --resume to continue it or --overwrite to start over"
            )
        shutil.rmtree(tmp)
    (tmp / "episodes").mkdir(parents=True)
    run_file.write_text(json.dumps(record, indent=2, sort_keys=True))


def _resume_finished(output_root: Path, tmp: Path, cfg: AugmentConfig) -> AugmentResult:
    """An existing output without --overwrite: only --resume of a run killed after its final rename is allowed."""
    if not cfg.resume:
        raise FileExistsError(f"the output {output_root} already exists; pass --overwrite to replace it")
    if not tmp.exists():
        raise FileExistsError(
            f"--resume: {output_root} exists and there is no interrupted run ({tmp}) to continue; "
            "it is complete already (pass --overwrite to redo it)"
        )
    # Killed after the final rename, before cleaning up: the output is complete.
    shutil.rmtree(tmp)
    summary = summarize(output_root)
    info = json.loads((output_root / "meta" / "info.json").read_text())
    return AugmentResult(
        output_root, info["total_episodes"], info["total_frames"], info["total_episodes"], summary
    )


def _checked_source_meta(cfg: AugmentConfig, source_root: Path):
    """The source dataset's metadata, after checking it has episodes and the cameras the attacks need."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    meta = LeRobotDataset(cfg.repo_id, root=source_root).meta
    if meta.total_episodes == 0:
        raise ValueError(f"{cfg.repo_id} ({source_root}) has no episodes to augment")
    if not meta.camera_keys and cfg.phantom.camera_attacks and cfg.phantom.rate > 0:
        raise ValueError(f"{cfg.repo_id} has no camera keys to attack with {cfg.phantom.camera_attacks}")
    if meta.camera_keys:  # unknown keys fail now, naming the dataset's keys
        cfg.phantom.resolve_cameras(list(meta.camera_keys))
    return meta


def _episode_jobs(cfg: AugmentConfig, meta, tmp: Path) -> list[_EpisodeJob]:
    jobs = []
    for position in range(meta.total_episodes):
        episode_index, start, stop = compat.episode_frame_range(meta, position)
        jobs.append(
            _EpisodeJob(
                position=position,
                episode_index=episode_index,
                start=start,
                stop=stop,
                staging_root=str(tmp / "episodes" / f"{episode_index:06d}"),
                repo_id=f"{cfg.output_repo_id}-episode-{episode_index:06d}",
            )
        )
    return jobs


def _write_episodes(
    cfg: AugmentConfig, plan: _Plan, jobs: list[_EpisodeJob], todo: list[_EpisodeJob]
) -> None:
    """Stage every episode still to do (in this process or a spawn pool), with one progress bar over frames."""
    total_frames = sum(job.stop - job.start for job in jobs)
    with tqdm(
        total=total_frames,
        initial=total_frames - sum(job.stop - job.start for job in todo),
        unit="frame",
        desc=f"augment {cfg.repo_id} -> {cfg.output_repo_id}",
        dynamic_ncols=True,
    ) as bar:
        if cfg.num_workers == 0:
            for job in todo:
                bar.update(_write_episode_with_context(plan, job))
        else:
            with ProcessPoolExecutor(max_workers=cfg.num_workers, mp_context=get_context("spawn")) as pool:
                futures = [pool.submit(_write_episode_in_worker, plan, job) for job in todo]
                for future in futures:  # in order, so an error is reported for the first failing episode
                    bar.update(future.result())


def _aggregate_and_publish(cfg: AugmentConfig, jobs, record: dict, tmp: Path, output_root: Path) -> dict:
    """Merge the staged episodes into one dataset and move it to ``output_root``; returns the attack summary."""
    aggregate_root = tmp / "aggregate"
    if aggregate_root.exists():
        shutil.rmtree(aggregate_root)
    compat.aggregate_datasets(
        repo_ids=[job.repo_id for job in jobs],
        roots=[Path(job.staging_root) for job in jobs],
        aggr_repo_id=cfg.output_repo_id,
        aggr_root=aggregate_root,
    )
    summary = summarize(aggregate_root)
    provenance = {"settings": record, "summary": summary}
    (aggregate_root / PROVENANCE_FILE).write_text(json.dumps(provenance, indent=2, sort_keys=True))
    if output_root.exists():  # --overwrite: the previous output goes only now that the new one is complete
        os.replace(output_root, tmp / "previous")
    os.replace(aggregate_root, output_root)
    shutil.rmtree(tmp)
    return summary


def augment(cfg: AugmentConfig) -> AugmentResult:
    """Write the augmented dataset described by ``cfg``; see the module docstring."""
    cfg.check_required()
    cfg.phantom.validate()
    source_root = _dataset_root(cfg.repo_id, cfg.root)
    output_root = _dataset_root(cfg.output_repo_id, cfg.output_root)
    _check_not_overlapping(source_root, output_root)
    tmp = temporary_dir(output_root)
    if output_root.exists() and not cfg.overwrite:
        return _resume_finished(output_root, tmp, cfg)

    meta = _checked_source_meta(cfg, source_root)
    record = _run_record(cfg, source_root, meta)
    _prepare_tmp(cfg, tmp, record)
    plan = _Plan(
        source_repo_id=cfg.repo_id,
        source_root=str(source_root),
        phantom=cfg.phantom,
        unit=cfg.unit,
        features=_output_features(meta, cfg.phantom),
        fps=int(meta.fps),
        robot_type=meta.robot_type,
        use_videos=len(meta.video_keys) > 0,
        vcodec=cfg.vcodec,
        parallel_encoding=cfg.num_workers == 0,
    )
    jobs = _episode_jobs(cfg, meta, tmp)
    for leftover in (tmp / "episodes").glob("*.partial"):
        shutil.rmtree(leftover)
    todo = [job for job in jobs if not Path(job.staging_root).exists()]
    _write_episodes(cfg, plan, jobs, todo)
    summary = _aggregate_and_publish(cfg, jobs, record, tmp, output_root)
    total_frames = sum(job.stop - job.start for job in jobs)
    return AugmentResult(output_root, len(jobs), total_frames, len(jobs) - len(todo), summary)


# -- CLI -----------------------------------------------------------------------------------------------------------
_FLAGS = ("resume", "overwrite")


def normalize_argv(argv: list[str]) -> list[str]:
    return normalize_cli_argv(argv, _FLAGS)


def main(argv: list[str] | None = None) -> None:
    """Entry point; bad flags, bad settings and refused outputs end with a one-line error (exit status 1)."""
    from lerobot_phantom import register

    register()  # the LeRobot registrations (attacks as image transforms, env and policy types)
    import draccus
    from datasets.utils.logging import disable_progress_bar

    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    disable_progress_bar()  # one bar (ours, in frames/s) instead of one per parquet file
    try:
        cfg = draccus.parse(AugmentConfig, args=normalize_argv(sys.argv[1:] if argv is None else list(argv)))
    except draccus.utils.ParsingError as err:
        # draccus reports "couldn't instantiate"; the reason (e.g. the list of valid attacks) is the cause.
        raise SystemExit(f"lerobot-phantom-augment: error: {err.__cause__ or err}") from err
    try:
        result = augment(cfg)
    except (ValueError, FileExistsError) as err:
        raise SystemExit(f"lerobot-phantom-augment: error: {err}") from err
    print(f"wrote {result.output_root} ({result.num_episodes} episodes, {result.num_frames} frames)")
    print(format_summary(result.summary))


if __name__ == "__main__":
    main()
