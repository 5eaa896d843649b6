"""Where the tests find the repository's files: its root, the example inputs and the test data."""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
DATA = ROOT / "tests" / "data"


def spacar_env() -> dict:
    """The environment of a `python -m spacar` subprocess that imports the spacar these tests
    import: the source tree's python/ with its built modules in development, the installed wheel
    in CI (where python/ holds no compiled module)."""
    import os

    import spacar

    return dict(os.environ, PYTHONPATH=str(Path(spacar.__file__).resolve().parents[1]))
