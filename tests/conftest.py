"""Test distribution over pytest-xdist workers (the README's test command runs ``-n auto --dist loadgroup``).

A group runs on one worker. Each test file is a group (its module fixtures and caches are built once: e.g. the
independent simulator's case reports, which the >= 90% naming test reads back), except the directories whose
``conftest.py`` builds session artefacts (a trained clean policy, image datasets): all their files share one group,
so the artefact is built once rather than once per worker.

Tests that draw fresh seeds each run (``CAMSIM_SEED``, ``STRIPES_SEED``; their failures report the seed to replay)
draw them once per run, in the controlling process, before the workers start: the workers inherit the
environment, so they collect the same cases and test the same draw. The run's last line names them.

Tests marked ``sampled`` (whole calibrations, 40 s to 6 min each) run in a seeded share per run (``SAMPLED_SHARE``,
``SAMPLED_SEED``: tests/sampling.py); every worker deselects the same ones, as it collects the same tests.

Workers share the cores: each gets its share of OpenMP threads (``OMP_NUM_THREADS``, which torch and OpenBLAS read
when they load), unless the environment already sets it. At torch's default, one thread per core in each of two
workers on two cores, a light projection selection took 298 s in the suite against 35 s alone (session 43,
docs/bench/session43).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import sampling

TESTS = Path(__file__).parent
SESSION_ARTEFACT_DIRS = ("train", "datasets")
FRESH_SEEDS = ("CAMSIM_SEED", "STRIPES_SEED", sampling.SEED_VARIABLE)
THREADS = "OMP_NUM_THREADS"


def pytest_configure(config: pytest.Config) -> None:
    if not hasattr(config, "workerinput"):  # the controller (or a run without workers): workers inherit these
        for name in FRESH_SEEDS:
            os.environ.setdefault(name, str(np.random.SeedSequence().entropy % 2**32))
        workers = config.getoption("numprocesses", default=None)  # an int once xdist resolved "auto"
        if isinstance(workers, int) and workers > 1:
            os.environ.setdefault(THREADS, str(max(1, (os.cpu_count() or 1) // workers)))


def pytest_terminal_summary(terminalreporter) -> None:
    seeds = " ".join(f"{name}={os.environ[name]}" for name in FRESH_SEEDS if name in os.environ)
    terminalreporter.write_line(f"fresh seeds of this run (set them to replay it): {seeds}")
    share = sampling.share_from_env()
    if share < 1.0:
        terminalreporter.write_line(
            f"sampled calibration checks: {share:g} of each file's ran ({sampling.SHARE_VARIABLE}=all runs every one)"
        )


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the marks into the test ids
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        relative = Path(item.path).relative_to(TESTS)
        shared = relative.parts[0] if relative.parts[0] in SESSION_ARTEFACT_DIRS else None
        item.add_marker(pytest.mark.xdist_group(shared or relative.as_posix()))
    left_out = sampled_out(config, items)
    if left_out:
        config.hook.pytest_deselected(items=left_out)
        dropped = {item.nodeid for item in left_out}
        items[:] = [item for item in items if item.nodeid not in dropped]


def named_on_command_line(config: pytest.Config, item: pytest.Item) -> bool:
    """Whether a command-line argument names ``item`` by its node id (a file with ``::`` and a test's name)."""
    for arg in config.args:
        path, _, name = arg.partition("::")
        same_file = Path(config.invocation_params.dir, path).resolve() == Path(item.path).resolve()
        if name and same_file and item.nodeid.partition("::")[2].startswith(name):
            return True
    return False


def sampled_out(config: pytest.Config, items: list[pytest.Item]) -> list[pytest.Item]:
    """The ``sampled`` tests this run leaves out: each file's drawn apart (``sampling.draw``) by the run's seed."""
    share = sampling.share_from_env()
    if share >= 1.0:
        return []
    seed = int(os.environ[sampling.SEED_VARIABLE])
    by_file: dict[str, list[pytest.Item]] = {}
    for item in items:
        if item.get_closest_marker("sampled") and not named_on_command_line(config, item):
            by_file.setdefault(Path(item.path).relative_to(TESTS).as_posix(), []).append(item)
    left_out = []
    for file, members in sorted(by_file.items()):
        kept = set(sampling.draw([m.nodeid for m in members], share, sampling.group_rng(seed, file)))
        left_out += [m for m in members if m.nodeid not in kept]
    return left_out
