"""Shared paths and texts of the input/output tests."""
import pytest

from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"


@pytest.fixture
def example_path():
    return EXAMPLE


@pytest.fixture
def example_text():
    return EXAMPLE.read_text()
