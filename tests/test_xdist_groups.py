"""The suite's parallel run (``-n auto --dist loadgroup``, tests/conftest.py) keeps a file's tests, and all of a
session-artefact directory's, on one worker, and every worker sees the run's one draw of the fresh seeds."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

CONFTEST = Path(__file__).with_name("conftest.py")

RECORDER = """import os, time
from pathlib import Path
import pytest
import torch

@pytest.mark.parametrize("i", range(4))
def test_record(i):
    time.sleep(0.2)  # long enough that both workers take work
    line = f"{__name__} {os.getpid()} {os.environ['CAMSIM_SEED']} {os.environ['STRIPES_SEED']} "
    line += f"{os.environ.get('OMP_NUM_THREADS')} {torch.get_num_threads()}\\n"
    with open(os.environ["RECORD"], "a") as record:
        record.write(line)
"""


@pytest.mark.parametrize("own_threads", [None, "2"], ids=["threads unset", "threads set"])
def test_files_and_session_artefact_dirs_stay_on_one_worker_and_share_the_seeds_and_the_cores(
    tmp_path, own_threads
):
    tests = tmp_path / "tests"
    (tests / "train").mkdir(parents=True)
    shutil.copy(CONFTEST, tests / "conftest.py")
    shutil.copy(CONFTEST.with_name("sampling.py"), tests / "sampling.py")
    for path in ("test_a.py", "test_b.py", "test_c.py", "train/test_one.py", "train/test_two.py"):
        (tests / path).write_text(RECORDER)
    (tmp_path / "pyproject.toml").write_text("")
    record = tmp_path / "record.txt"
    env = {k: v for k, v in os.environ.items() if k not in ("CAMSIM_SEED", "STRIPES_SEED", "OMP_NUM_THREADS")}
    if own_threads is not None:
        env["OMP_NUM_THREADS"] = own_threads
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-n",
            "2",
            "--dist",
            "loadgroup",
            "-p",
            "no:cacheprovider",
            "tests",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env={**env, "RECORD": str(record), "PYTHONDONTWRITEBYTECODE": "1"},
        timeout=300,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    rows = [line.split() for line in record.read_text().splitlines()]
    assert len(rows) == 20
    workers: dict[str, set[str]] = {}
    for module, pid, *_ in rows:
        group = "train" if module in ("test_one", "test_two") else module
        workers.setdefault(group, set()).add(pid)
    assert all(len(pids) == 1 for pids in workers.values()), workers
    assert len({pid for _, pid, *_ in rows}) == 2  # the run did use both workers
    seeds = {tuple(row[2:4]) for row in rows}
    assert len(seeds) == 1, seeds
    camsim, stripes = seeds.pop()
    assert f"CAMSIM_SEED={camsim} STRIPES_SEED={stripes}" in run.stdout  # the run names its draw for a replay
    # two workers split the cores between them; a user's own thread count is kept
    expected = own_threads or str(max(1, (os.cpu_count() or 1) // 2))
    assert {tuple(row[4:]) for row in rows} == {(expected, expected)}
