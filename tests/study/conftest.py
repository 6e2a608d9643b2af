"""Shared fixtures of the study tests: a microscopic study on the tiny CPU configs."""

import pytest
from study_testkit import micro_config

from lerobot_phantom.study.config import StudyConfig


@pytest.fixture
def micro(tmp_path) -> StudyConfig:
    return micro_config(tmp_path / "study")
