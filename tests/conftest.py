"""Test distribution over pytest-xdist workers (the README's test command runs ``-n auto --dist loadgroup``).

A group runs on one worker. Each test file is a group (its module fixtures and caches are built once: e.g. the
independent simulator's case reports, which the >= 90% naming test reads back), except the directories whose
``conftest.py`` builds session artefacts (a trained clean policy, image datasets): all their files share one group,
so the artefact is built once rather than once per worker.

Tests that draw fresh seeds each run (``CAMSIM_SEED``, ``STRIPES_SEED``; their failures report the seed to replay)
draw them once per run, in the controlling process, before the workers start: the workers inherit the
environment, so they collect the same cases and test the same draw. The run's last line names them.

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

TESTS = Path(__file__).parent
SESSION_ARTEFACT_DIRS = ("train", "datasets")
FRESH_SEEDS = ("CAMSIM_SEED", "STRIPES_SEED")
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


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which reads the marks into the test ids
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        relative = Path(item.path).relative_to(TESTS)
        shared = relative.parts[0] if relative.parts[0] in SESSION_ARTEFACT_DIRS else None
        item.add_marker(pytest.mark.xdist_group(shared or relative.as_posix()))
