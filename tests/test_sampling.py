"""The suite's sampled calibration checks (tests/sampling.py, tests/conftest.py): a seeded share of each file's runs,
the same on every worker, every one with ``SAMPLED_SHARE=all`` or when named on the command line."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sampling

TESTS = Path(__file__).parent

SAMPLED_FILE = """import os
import pytest

@pytest.mark.sampled
@pytest.mark.parametrize("i", range(10))
def test_sampled(i):
    with open(os.environ["RECORD"], "a") as record:
        record.write(f"sampled {i} {os.environ['SAMPLED_SEED']}\\n")

def test_always():
    with open(os.environ["RECORD"], "a") as record:
        record.write("always\\n")
"""


def test_share_is_read_from_the_environment_and_bad_values_name_the_valid_ones():
    assert sampling.share_from_env({}) == sampling.DEFAULT_SHARE
    assert sampling.share_from_env({"SAMPLED_SHARE": "all"}) == 1.0
    assert sampling.share_from_env({"SAMPLED_SHARE": " 0.5 "}) == 0.5
    for bad in ("0", "1.5", "-0.2", "half", "nan"):
        with pytest.raises(ValueError, match=r"SAMPLED_SHARE=.*expected 'all' or a share in \(0, 1\]"):
            sampling.share_from_env({"SAMPLED_SHARE": bad})


def test_a_draw_keeps_the_share_on_average_and_its_order():
    names = [f"t{i}" for i in range(3)]
    counts = []
    for seed in range(2000):
        chosen = sampling.draw(names, 0.2, sampling.group_rng(seed, "file.py"))
        assert chosen == sorted(chosen, key=names.index)
        counts.append(len(chosen))
    # 3 tests at a fifth: none or one a run (never two), 0.6 on average
    assert set(counts) == {0, 1}
    assert np.mean(counts) == pytest.approx(0.6, abs=0.04)
    assert sampling.draw(names, 1.0, sampling.group_rng(0, "f")) == names
    assert len(sampling.draw(names, 0.2, sampling.group_rng(0, "f"), at_least=2)) == 2


def test_a_draw_follows_the_seed_and_the_group():
    names = [f"t{i}" for i in range(20)]
    once = sampling.draw(names, 0.3, sampling.group_rng(7, "a.py"))
    assert once == sampling.draw(names, 0.3, sampling.group_rng(7, "a.py"))
    others = {
        tuple(sampling.draw(names, 0.3, sampling.group_rng(s, g))) for s in (7, 8) for g in ("a.py", "b.py")
    }
    assert len(others) > 1


def run_suite(tmp_path: Path, *args: str, **env_extra: str) -> tuple[subprocess.CompletedProcess, list[str]]:
    tests = tmp_path / "tests"
    if not tests.exists():
        tests.mkdir()
        shutil.copy(TESTS / "conftest.py", tests)
        shutil.copy(TESTS / "sampling.py", tests)
        (tests / "test_checks.py").write_text(SAMPLED_FILE)
        (tmp_path / "pyproject.toml").write_text(
            '[tool.pytest.ini_options]\nmarkers = ["sampled: a share runs"]\naddopts = "--strict-markers"\n'
        )
    record = tmp_path / "record.txt"
    record.unlink(missing_ok=True)
    env = {k: v for k, v in os.environ.items() if k not in ("SAMPLED_SHARE", "SAMPLED_SEED")}
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env={**env, **env_extra, "RECORD": str(record), "PYTHONDONTWRITEBYTECODE": "1"},
        timeout=300,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    return run, record.read_text().splitlines()


def test_each_run_draws_its_share_the_same_on_every_worker_and_a_seed_replays_it(tmp_path):
    run, rows = run_suite(tmp_path, "-n", "2", "--dist", "loadgroup", "tests", SAMPLED_SHARE="0.3")
    sampled = sorted(row for row in rows if row.startswith("sampled"))
    assert rows.count("always") == 1
    assert len(sampled) == 3, rows  # 0.3 of 10, a whole number: exactly 3
    seed = sampled[0].split()[2]
    assert f"SAMPLED_SEED={seed}" in run.stdout and "SAMPLED_SHARE=all runs every one" in run.stdout
    _, replayed = run_suite(tmp_path, "tests", SAMPLED_SHARE="0.3", SAMPLED_SEED=seed)
    assert sorted(row for row in replayed if row.startswith("sampled")) == sampled


def test_all_runs_every_check_and_a_named_check_always_runs(tmp_path):
    run, rows = run_suite(tmp_path, "tests", SAMPLED_SHARE="all")
    assert len([row for row in rows if row.startswith("sampled")]) == 10
    assert "sampled calibration checks" not in run.stdout
    # named by node id, a check runs whatever the draw: here the draw alone would leave it out
    named = "tests/test_checks.py::test_sampled[4]"
    assert sampling.draw([named], 0.01, sampling.group_rng(1, "test_checks.py")) == []
    _, rows = run_suite(tmp_path, named, SAMPLED_SHARE="0.01", SAMPLED_SEED="1")
    assert [row.split()[:2] for row in rows] == [["sampled", "4"]]


def test_a_bad_share_stops_the_run_with_the_valid_values(tmp_path):
    with pytest.raises(AssertionError, match=r"expected 'all' or a share in \(0, 1\]"):
        run_suite(tmp_path, "tests", SAMPLED_SHARE="everything")
