"""Shared fixtures: paths of the shipped models."""
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def examples() -> Path:
    return ROOT / "examples"


@pytest.fixture
def data() -> Path:
    return ROOT / "tests" / "data"
