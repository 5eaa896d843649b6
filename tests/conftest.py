"""Shared paths and texts of the input/output tests."""
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "slidercrank.dat"


@pytest.fixture
def example_path():
    return EXAMPLE


@pytest.fixture
def example_text():
    return EXAMPLE.read_text()
