"""Test distribution over pytest-xdist workers (the README's test command runs ``-n auto --dist loadgroup``).

A group runs on one worker. Each test file is a group (its module fixtures and caches are built once: e.g. the
independent simulator's case reports, which the >= 90% naming test reads back), except the directories whose
``conftest.py`` builds session artefacts (a trained clean policy, image datasets): all their files share one group,
so the artefact is built once rather than once per worker.
"""

from __future__ import annotations

from pathlib import Path

import pytest

TESTS = Path(__file__).parent
SESSION_ARTEFACT_DIRS = ("train", "datasets")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        relative = Path(item.path).relative_to(TESTS)
        shared = relative.parts[0] if relative.parts[0] in SESSION_ARTEFACT_DIRS else None
        item.add_marker(pytest.mark.xdist_group(shared or relative.as_posix()))
