"""The model that results keep (spacar.static, spacar.simulate): a copy of the model as it was at
the solve, made only when it is first needed (``_core.LazyModelCopy`` in a ``KeptModel``: when
the model changes next, is deleted, or when the copy is read). Every way of changing the model
must make the copy first: the results then draw, label and take compliance from the model of
their solve, never a later one."""
from __future__ import annotations

import gc
import pickle

import numpy as np
import pytest

import spacar
from spacar.results import KeptModel
from support.paths import EXAMPLES


def cantilever(n=4, P=1.0):
    """n PLBEAMs along x, clamped at nodes 1, 2; tip load P along y on node 2n+1."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n, 0.0)
        m.estiff(k, 0.0, 1.0)
        m.dyne(k, 2, 3)
    m.fix(1)
    m.fix(2)
    m.force(2 * n + 1, 0.0, P)
    return m


def state(model) -> bytes:
    """Everything the model holds (its pickle: nodes, elements, settings, state)."""
    return pickle.dumps(model.core)


# Changes after the solve: each goes through a different path of the core (a builder method, a
# setting, a new block's state stored by an analysis, the model's deletion).
CHANGES = {
    "force": lambda m: m.force(9, 0.0, 2.0),
    "estiff": lambda m: m.estiff(2, 0.0, 3.0),
    "mass and class": lambda m: (m.mass(5, 0.5), m.fix(5)),
    "setting": lambda m: m.epskin(1e-9),
    "another static": lambda m: spacar.static(m, steps=1),
    "compliance of the live model": lambda m: (m.force(9, 0.0, 2.0), spacar.compliance(m, 9)),
    "linearize": lambda m: (m.xd(9, 1, 0.5), spacar.linearize(m)),
}


@pytest.mark.parametrize("change", CHANGES)
def test_results_keep_the_model_of_their_solve(change):
    model = cantilever()
    res = spacar.static(model, steps=1)
    at_solve = state(model)
    geometry = spacar.Geometry.from_model(model)
    CHANGES[change](model)
    assert state(model) != at_solve
    assert res.geometry == geometry
    kept = res._static_model()  # compliance's model (spacar.compliance(res, node))
    assert state(kept) == at_solve
    assert res.dof_labels == [f"e({k},{i}) PLBEAM" for k in range(1, 5) for i in (2, 3)]


def test_compliance_takes_the_loads_of_the_solve():
    model = cantilever(P=1.0)
    res = spacar.static(model, steps=1)
    expected = spacar.compliance(res, 9)
    model.force(9, 0.0, 2.5)   # a heavier load later: the compliance of res stays that of P = 1
    spacar.static(model, steps=1)
    np.testing.assert_array_equal(spacar.compliance(res, 9), expected)


def test_an_unchanged_model_is_copied_when_read():
    model = cantilever()
    res = spacar.static(model, steps=1)
    assert isinstance(res._geometry_source, KeptModel)
    assert res.geometry == spacar.Geometry.from_model(model)
    assert state(res._static_model()) == state(model)


def test_a_deleted_model_leaves_its_copy():
    model = cantilever()
    res = spacar.static(model, steps=1)
    at_solve, geometry = state(model), spacar.Geometry.from_model(model)
    del model
    gc.collect()
    assert res.geometry == geometry
    assert state(res._static_model()) == at_solve


def test_simulation_results_keep_their_model():
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    res = spacar.simulate(model)
    geometry = spacar.Geometry.from_model(model)
    model.mass(8, 0.5)
    model.timestep(5, 0.05)
    spacar.simulate(model)   # stores a new state in the model
    assert res.geometry == geometry


def test_each_copy_is_its_own():
    """Two results of one model each keep their own solve; a copy of the model has no pending
    copies of the original (changing it leaves the original's results alone)."""
    model = cantilever(P=1.0)
    first = spacar.static(model, steps=1)
    s1 = state(model)
    model.force(9, 0.0, 2.0)
    second = spacar.static(model, steps=1)
    s2 = state(model)
    other = model.copy()
    other.force(9, 0.0, 3.0)
    assert state(first._static_model()) == s1
    assert state(second._static_model()) == s2


def test_a_copy_read_first_stays_when_the_model_changes():
    model = cantilever()
    res = spacar.static(model, steps=1)
    at_solve = state(model)
    labels = res.dof_labels                 # the kept model made now, from the unchanged model
    model.force(9, 0.0, 2.0)
    spacar.static(model, steps=1)
    assert state(res._static_model()) == at_solve and res.dof_labels == labels
    # one copy serves the labels, the geometry and compliance
    assert res._static_model().core is res._geometry_source.core()
