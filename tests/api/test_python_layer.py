"""The Python layer's shared pieces (issue 18): the public handle to the core model, the one
keyword-argument grouping, the one tqdm detection and the one R(λ)."""
import re

import spacar
from spacar import _core
from spacar.geometry import Geometry
from support.paths import EXAMPLES, ROOT

EXAMPLE = EXAMPLES / "slidercrank.dat"


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


def test_reader_and_builder_group_the_values_of_a_line_alike():
    from spacar.io.reader import _parse_line
    from spacar.keywords import KEYWORDS
    from spacar.model import check_args

    # MASS n m(1..6): the node, then up to six masses; X n x(1..4) likewise.
    assert KEYWORDS["MASS"].counts(4) == [1, 3] and KEYWORDS["X"].counts(7) == [1, 4]
    assert KEYWORDS["FIX"].counts(1) == [1, 0]
    for kw in KEYWORDS.values():
        least = sum(p.count_min for p in kw.params)
        for n in range(least, least + 5):
            values = _parse_line(kw, ["1"] * n)
            try:
                groups = check_args(kw, values)
            except spacar.InputError:
                assert n > sum(p.count_max for p in kw.params), kw.name   # too many values
                continue
            sizes = [1 if p.count_min == p.count_max == 1 else len(g) for p, g in zip(kw.params, groups)]
            assert sizes == kw.counts(n), kw.name


def test_sweep_and_simulate_detect_a_jupyter_kernel_alike(capsys, monkeypatch):
    # sweep.py had its own detection: a terminal only (no bar by default in Jupyter), and always
    # tqdm.auto, whose notebook bar fails without ipywidgets. Both now follow spacar.progress: a
    # Jupyter kernel is interactive; without ipywidgets the text bar shows.
    import sys
    import types

    import pytest

    import spacar.progress

    tqdm = pytest.importorskip("tqdm")
    monkeypatch.setitem(sys.modules, "ipykernel", types.ModuleType("ipykernel"))
    monkeypatch.setattr(spacar.progress, "in_kernel", lambda: True)   # a running kernel (get_ipython().kernel)
    monkeypatch.setitem(sys.modules, "ipywidgets", None)   # import ipywidgets now fails
    monkeypatch.delenv("SPACAR_PROGRESS", raising=False)
    assert spacar.progress.interactive() and spacar.progress.automatic()
    assert spacar.progress.tqdm_class() is tqdm.tqdm
    spacar.sweep(spacar.read(EXAMPLE), {"XD 2 1": [1.0, 2.0], "TIMESTEP": [(1, 0.05)]}, workers=1)
    assert "spacar.sweep" in capsys.readouterr().err
    monkeypatch.setenv("SPACAR_PROGRESS", "0")             # the one switch turns both off
    assert not spacar.progress.automatic()
    spacar.sweep(spacar.read(EXAMPLE), {"XD 2 1": [1.0, 2.0], "TIMESTEP": [(1, 0.05)]}, workers=1)
    assert capsys.readouterr().err == ""


def test_one_rotation_matrix_of_euler_parameters():
    import numpy as np

    import spacar.geometry
    from spacar.compare import _topology

    assert _topology.rotation is spacar.geometry.rotation and not hasattr(_topology, "rot_lambda")
    # λ = (1, 1, −1, 1)/2: 120° about (1, −1, 1)/√3, which takes e_x to e_z, e_y to −e_x, e_z to −e_y
    R = spacar.geometry.rotation([0.5, 0.5, -0.5, 0.5])
    np.testing.assert_allclose(R, [[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]], atol=1e-15)


def test_one_union_find_of_rigid_bodies():
    from spacar.compare import _topology

    # links sharing a node are one body; a node of no link is a body; link nodes are added
    assert _core.rigid_bodies([5, 1, 9], [[3, 2], [2, 7], [9, 4]]) == [[1], [2, 3, 7], [4, 9], [5]]
    assert _core.rigid_bodies([], []) == [] and _core.rigid_bodies([4], [[4, 4]]) == [[4]]
    assert not hasattr(_topology, "_union_find")     # spacar.compare groups with the core's
    # the manual's slider-crank: the rigid crank (BETA 2, 4) is the one rigid body besides the
    # ground; the BETA nodes of the flexible rod (beams 2, 3) belong to none
    model = spacar.read(EXAMPLE)
    assert [b.orientation_nodes for b in _topology.analyse(model).bodies] == [[], [2, 4]]
