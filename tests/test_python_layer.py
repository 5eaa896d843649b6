"""The Python layer's shared pieces (issue 18): the public handle to the core model, the one
keyword-argument grouping, the one tqdm detection and the one R(λ)."""
import re
from pathlib import Path

import spacar
from spacar import _core
from spacar.geometry import Geometry

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "slidercrank.dat"


def test_model_core_is_the_core_model_itself():
    model = spacar.read(EXAMPLE)
    assert isinstance(model.core, _core.Model) and model.core is model.core
    model.prepare()
    assert model.core.frozen                         # the handle sees what the Model does
    assert Geometry.from_model(model) == Geometry.from_model(model.core)
    copy = model.copy()
    assert copy.core is not model.core and copy.core.frozen


def test_no_module_but_model_reaches_into_the_private_core():
    package = ROOT / "python" / "spacar"
    for path in package.rglob("*.py"):
        if path.name != "model.py":
            assert not re.search(r"\b(?!spacar\b)\w+\._core\b", path.read_text()), path  # spacar._core: the module
