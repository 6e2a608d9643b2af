"""``lerobot-phantom-study``: run (or continue) the whole study in one directory.

    lerobot-phantom-study --output_dir=docs/study --collect.episodes=100 --lora.steps=1000 --sweep.n_episodes=50

Each stage runs an existing CLI (as a subprocess with one torch thread unless ``--threads``), its output streamed
to ``logs/<stage>.log``. ``study.json`` records, per stage, the command, its fingerprint, status and wall time; a
second invocation skips finished stages whose fingerprint is unchanged, continues an interrupted training run
with LeRobot's ``--resume`` and an interrupted sweep condition by condition, and re-runs a stage (and the stages
after it) whose settings changed.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import os
import platform
import shlex
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import asdict
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from tqdm import tqdm

import lerobot_phantom
from lerobot_phantom.study.config import StudyConfig
from lerobot_phantom.study.stages import (
    EVAL_FILE,
    PRETRAINED,
    REPORT,
    RESUME,
    RUN,
    SELECT,
    SELECTION_FILE,
    SKIP,
    SWEEP,
    Stage,
    decide,
    fingerprints,
    plan,
)

MANIFEST = "study.json"
MANIFEST_FORMAT = "lerobot_phantom.study/1"
CONFIG_FILE = "study_config.json"

# Console script -> module whose main() it calls (the same mapping as pyproject's [project.scripts]).
MODULES = {
    "lerobot-phantom-collect": "lerobot_phantom.envs.collect",
    "lerobot-phantom-make-vlm": "lerobot_phantom.train.make_vlm",
    "lerobot-phantom-train": "lerobot_phantom.train.train",
    "lerobot-phantom-eval": "lerobot_phantom.eval.eval",
    "lerobot-phantom-report": "lerobot_phantom.eval.report",
    "lerobot-phantom-select-checkpoint": "lerobot_phantom.eval.select_checkpoint",
}


def git_commit() -> str | None:
    """The commit of the package's source tree, or None outside a git checkout."""
    repo = Path(lerobot_phantom.__file__).resolve().parents[1]
    result = subprocess.run(
        ["git", "-C", str(repo), "rev-parse", "HEAD"], capture_output=True, text=True, check=False
    )
    return result.stdout.strip() if result.returncode == 0 else None


def versions() -> dict[str, str]:
    from importlib.metadata import version

    return {
        "lerobot_phantom": lerobot_phantom.__version__,
        "lerobot": version("lerobot"),
        "torch": version("torch"),
        "python": platform.python_version(),
    }


def read_manifest(study_dir: Path) -> dict[str, Any]:
    path = study_dir / MANIFEST
    if not path.is_file():
        return {}
    manifest = json.loads(path.read_text())
    if manifest.get("format") != MANIFEST_FORMAT:
        raise ValueError(f"{path} is not a lerobot-phantom-study manifest (format {MANIFEST_FORMAT})")
    return manifest


def write_manifest(study_dir: Path, manifest: dict[str, Any]) -> None:
    """Atomically (an interrupted write never leaves a truncated study.json)."""
    tmp = study_dir / f".{MANIFEST}.tmp"
    tmp.write_text(json.dumps(manifest, indent=2))
    tmp.replace(study_dir / MANIFEST)


def stage_env(threads: int) -> dict[str, str]:
    """One torch/OpenMP thread per process unless configured (a user's own OMP_NUM_THREADS does not win here:
    the study's setting is recorded in study.json)."""
    n = str(threads)
    return {**os.environ, "OMP_NUM_THREADS": n, "MKL_NUM_THREADS": n, "HF_HUB_OFFLINE": "1"}


def run_subprocess(argv: list[str], study_dir: Path, log, cfg: StudyConfig) -> None:
    """The stage's CLI as a subprocess in the study directory, output to the log (and the terminal if verbose)."""
    threads, verbose = cfg.threads, cfg.verbose
    module = MODULES[argv[0]]
    command = [sys.executable, "-c", f"import sys; from {module} import main; sys.exit(main())", *argv[1:]]
    process = subprocess.Popen(
        command, cwd=study_dir, env=stage_env(threads), stdout=subprocess.PIPE, stderr=subprocess.STDOUT
    )
    for chunk in iter(lambda: process.stdout.read1(4096), b""):
        log.write(chunk)
        if verbose:
            sys.stderr.buffer.write(chunk)
            sys.stderr.flush()
    if process.wait() != 0:
        raise RuntimeError(f"{argv[0]} failed (exit {process.returncode}); its output is in {log.name}")


@contextlib.contextmanager
def inside(study_dir: Path, argv: list[str]):
    cwd, saved = Path.cwd(), sys.argv
    os.chdir(study_dir)
    sys.argv = list(argv)
    try:
        yield
    finally:
        os.chdir(cwd)
        sys.argv = saved


def run_in_process(argv: list[str], study_dir: Path, log, cfg: StudyConfig) -> None:
    """The stage's CLI in this process (tests): same command line, same working directory."""
    log.write(b"(run in process)\n")
    with inside(study_dir, argv), contextlib.redirect_stdout(sys.stderr):
        importlib.import_module(MODULES[argv[0]]).main()


def clear(path: Path) -> None:
    """Remove a stage's own output (never anything outside the study directory)."""
    if path.is_dir():
        shutil.rmtree(path)
    elif path.exists():
        path.unlink()


class Study:
    """One invocation: decides, runs and records every stage."""

    def __init__(self, cfg: StudyConfig, invocation: list[str], runner: Callable | None = None) -> None:
        self.cfg = cfg
        # runner(argv, study_dir, log, cfg) runs one command line; tests may pass their own.
        self.runner = runner or (run_in_process if cfg.in_process else run_subprocess)
        # stages running side by side (--jobs) update the records and write the manifest one at a time
        self.lock = threading.RLock()
        self.dir = Path(cfg.output_dir).resolve()
        self.stages = plan(cfg)
        self.fingerprints = fingerprints(self.stages)
        previous = read_manifest(self.dir)
        self.records: dict[str, dict[str, Any]] = previous.get("stages", {})
        self.manifest: dict[str, Any] = {
            "format": MANIFEST_FORMAT,
            # Re-runs (or continues) this study from the directory the study was started in.
            "command": ["lerobot-phantom-study", f"--config_path={Path(cfg.output_dir) / CONFIG_FILE}"],
            "invocation": invocation,
            "config": json.loads(json.dumps(asdict(cfg))),  # as study.json stores it (tuples -> lists)
            "seeds": {
                "collect": cfg.collect.seed,
                "train": cfg.train.seed,
                "lora": cfg.lora.seed,
                "sweep_env_seeds": [cfg.sweep.seed, cfg.sweep.seed + cfg.sweep.n_episodes - 1],
            },
            "versions": versions(),
            "git_commit": git_commit(),
            "threads": cfg.threads,
            "started": datetime.now(UTC).isoformat(timespec="seconds"),
            "stages": self.records,
            "last_invocation": {},
            "results": {},
        }

    def save(self) -> None:
        self.manifest["results"] = self.results()
        self.manifest["conditions"] = {
            role: json.loads((self.dir / path).read_text())["metadata"].get("conditions", [])
            for role, path in self.manifest["results"].items()
        }
        report = self.records.get("report", {})
        self.manifest["report"] = report["output"] if report.get("status") == "done" else None
        self.manifest["selection"] = self.selection()
        write_manifest(self.dir, self.manifest)

    def results(self) -> dict[str, str]:
        """Sweep role -> its eval.json, relative to the study directory, for every finished sweep."""
        return {
            stage.role: f"{stage.output}/{EVAL_FILE}"
            for stage in self.stages
            if stage.kind == SWEEP
            and stage.role is not None
            and self.records.get(stage.name, {}).get("status") == "done"
        }

    def selection(self) -> str | None:
        """selection.json of the checkpoint selection, relative to the study directory, once it is done."""
        for stage in self.stages:
            if stage.kind == SELECT and self.records.get(stage.name, {}).get("status") == "done":
                return f"{stage.output}/{SELECTION_FILE}"
        return None

    def run_stage(self, stage: Stage, decision: str) -> None:
        fp = self.fingerprints[stage.name]
        argv = stage.resume_argv() if decision == RESUME else stage.argv
        with self.lock:
            if decision == RUN:
                clear(self.dir / stage.output)
            record = self.records.get(stage.name) if decision == RESUME else None
            record = record or {"wall_s": 0.0, "runs": []}
            record.update(status="running", fingerprint=fp, argv=stage.argv, output=stage.output)
            record.update(log=f"logs/{stage.name}.log", depends=list(stage.depends))
            # a study resumed from another checkout runs its later stages with other code: each run names its own
            started_at = datetime.now(UTC).isoformat(timespec="seconds")
            run = {
                "argv": argv,
                "action": decision,
                "git_commit": self.manifest["git_commit"],
                "started": started_at,
            }
            record["runs"] = [*record["runs"], run]
            self.records[stage.name] = record
            self.save()
        started = time.time()
        with open(self.dir / record["log"], "ab") as log:
            log.write(f"\n$ {shlex.join(argv)}\n".encode())
            log.flush()
            self.runner(argv, self.dir, log, self.cfg)
        wall = time.time() - started
        with self.lock:
            record["runs"][-1]["wall_s"] = round(wall, 3)
            record.update(status="done", wall_s=round(record["wall_s"] + wall, 3))
            self.save()

    def decisions(self) -> dict[str, str]:
        """What this invocation would do with each stage (--dry_run), assuming every stage that runs succeeds."""
        out: dict[str, str] = {}
        for stage in self.stages:
            upstream_ran = any(out.get(d) in (RUN, RESUME) for d in stage.depends)
            out[stage.name] = decide(
                stage, self.fingerprints[stage.name], self.records.get(stage.name), self.dir, upstream_ran
            )
        return out

    def decide(self, stage: Stage, done: dict[str, str]) -> str:
        """Skip, resume or run ``stage``, given what this invocation did with the stages before it."""
        upstream_ran = any(done.get(d) in (RUN, RESUME) for d in stage.depends)
        decision = decide(
            stage, self.fingerprints[stage.name], self.records.get(stage.name), self.dir, upstream_ran
        )
        done[stage.name] = self.manifest["last_invocation"][stage.name] = decision
        return decision

    def run(self) -> dict[str, Any]:
        started = time.time()
        (self.dir / "logs").mkdir(parents=True, exist_ok=True)
        (self.dir / CONFIG_FILE).write_text(json.dumps(asdict(self.cfg), indent=2))
        progress = tqdm(self.stages, desc="study", unit="stage", disable=not self.cfg.verbose)
        if self.cfg.jobs > 1:
            self.run_side_by_side(progress)
        else:
            done: dict[str, str] = {}
            for stage in progress:
                progress.set_postfix_str(stage.name)
                decision = self.decide(stage, done)
                if decision == SKIP:
                    self.save()
                    continue
                self.run_stage(stage, decision)
        progress.close()
        # Records of stages no longer in the plan (e.g. an optional stage switched off) are kept but marked.
        for name, record in self.records.items():
            record["in_plan"] = name in self.fingerprints
        self.manifest["wall_s"] = round(time.time() - started, 3)
        self.save()
        return self.manifest

    def run_side_by_side(self, progress: tqdm) -> None:
        """Up to ``jobs`` stages at once, each started (in plan order) once every stage it depends on has finished.

        A failing stage stops new starts; the stages still running finish (and are recorded) before its error is
        raised, so a second invocation resumes exactly what is missing."""
        done: dict[str, str] = {}
        finished: set[str] = set()
        waiting = list(self.stages)
        running: dict[Future, Stage] = {}
        failure: BaseException | None = None
        with ThreadPoolExecutor(max_workers=self.cfg.jobs) as pool:
            while (waiting and failure is None) or running:
                ready = [s for s in waiting if all(d in finished for d in s.depends)]
                skipped = False
                for stage in ready if failure is None else []:
                    if len(running) >= self.cfg.jobs:
                        break
                    waiting.remove(stage)
                    with self.lock:
                        decision = self.decide(stage, done)
                        if decision == SKIP:
                            self.save()
                    if decision == SKIP:
                        finished.add(stage.name)
                        progress.update()
                        skipped = True
                        continue
                    running[pool.submit(self.run_stage, stage, decision)] = stage
                if not running:
                    if skipped:
                        continue  # only skipped stages were ready: their dependants may be ready now
                    blocked = {s.name: [d for d in s.depends if d not in finished] for s in waiting}
                    raise RuntimeError(f"stages wait for stages that never finish: {blocked}")
                completed, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in completed:
                    stage = running.pop(future)
                    if future.exception() is not None:
                        failure = failure or future.exception()
                        continue
                    finished.add(stage.name)
                    progress.update()
                    progress.set_postfix_str(", ".join(s.name for s in running.values()))
        if failure is not None:
            raise failure


CURSOR_UP = b"\x1b[A"  # what tqdm writes after a nested bar to return to the line above


def final_progress_states(log: bytes) -> bytes:
    """A stage log as a terminal would leave it: progress bars redrawn in place (carriage returns, and tqdm's
    cursor-up after a nested bar) keep only their last state; every other line of output stays (a 25-condition
    sweep's log shrinks from 2.7 MB to 5 kB)."""
    rows, cursor = [b""], 0
    for index, segment in enumerate(log.split(b"\n")):
        if index:
            cursor += 1
            if cursor == len(rows):
                rows.append(b"")
        for part in segment.split(b"\r"):
            # A part is written from the line's start (after a newline or a carriage return); an empty one leaves it.
            text = part.replace(CURSOR_UP, b"")
            if text:
                rows[cursor] = text
            cursor = max(0, cursor - part.count(CURSOR_UP))
    return b"\n".join(rows)


def publish(study_dir: Path, destination: Path) -> list[Path]:
    """Copy what a reader of the study needs to ``destination`` (logs with progress bars at their final state,
    configs, evaluations, report; no data, VLM or weights); returns the files written.

    The copy keeps the study's layout, so every path in ``study.json`` (``results``, ``report``, ``log``) stays valid
    relative to ``destination``. Only finished stages are copied: a sweep still running is left out, and the copied
    manifest lists what was published. The study directory itself is never written to.
    """
    study_dir, destination = study_dir.resolve(), destination.resolve()
    manifest = read_manifest(study_dir)
    if not manifest:
        raise FileNotFoundError(f"{study_dir} holds no {MANIFEST}: nothing to publish")
    if destination == study_dir or study_dir in destination.parents:
        raise ValueError(f"--publish_to must lie outside the study directory {study_dir}, got {destination}")
    if destination.is_dir() and any(destination.iterdir()) and not (destination / MANIFEST).is_file():
        raise FileExistsError(
            f"{destination} is not empty and holds no {MANIFEST} of an earlier publication; choose another directory"
        )
    done = {name: r for name, r in manifest.get("stages", {}).items() if r.get("status") == "done"}
    sources = [Path(CONFIG_FILE)]
    for name, record in done.items():
        output = Path(record["output"])
        sources.append(Path(record["log"]))
        if name.startswith(f"{SWEEP}_") or name == REPORT:
            sources += [
                p.relative_to(study_dir) for p in sorted((study_dir / output).rglob("*")) if p.is_file()
            ]
        elif (study_dir / output / SELECTION_FILE).is_file():
            sources.append(output / SELECTION_FILE)
        elif (study_dir / output / PRETRAINED / "train_config.json").is_file():
            sources.append(output / PRETRAINED / "train_config.json")
    written = []
    for relative in sources:
        target = destination / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        if relative.suffix == ".log":
            target.write_bytes(final_progress_states(study_dir.joinpath(relative).read_bytes()))
        else:
            shutil.copyfile(study_dir / relative, target)
        written.append(target)
    published = {**manifest, "published": {"from": str(study_dir), "stages": sorted(done)}}
    write_manifest(destination, published)
    return [*written, destination / MANIFEST]


def run_study(
    cfg: StudyConfig, invocation: list[str] | None = None, runner: Callable | None = None
) -> dict[str, Any]:
    """Run or continue the study in ``cfg.output_dir``; returns the manifest (also in ``study.json``)."""
    return Study(cfg, invocation or ["lerobot-phantom-study"], runner).run()


def main(args: list[str] | None = None) -> None:
    import draccus

    from lerobot_phantom import register

    register()  # the LeRobot registrations, as every lerobot-phantom-* script does

    argv = sys.argv[1:] if args is None else list(args)
    cfg = draccus.parse(StudyConfig, args=argv)
    if cfg.publish_to is not None:
        written = publish(Path(cfg.output_dir), Path(cfg.publish_to))
        print(f"published {len(written)} files of {cfg.output_dir} to {cfg.publish_to}")
        return
    if cfg.dry_run:
        for name, decision in Study(cfg, ["lerobot-phantom-study", *argv]).decisions().items():
            print(f"{decision:>6}  {name}")
        return
    manifest = run_study(cfg, ["lerobot-phantom-study", *argv])
    study_dir = Path(cfg.output_dir)
    print(f"study in {study_dir}: " + ", ".join(f"{k} {v}" for k, v in manifest["last_invocation"].items()))
    summary = study_dir / "report" / "summary.md"
    if summary.is_file():
        print(summary.read_text())


if __name__ == "__main__":
    main()
