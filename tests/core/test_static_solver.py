"""spacar.StaticSolver (issue 34): the static analysis set up once and solved many times. Each
call must give spacar.static's results to the last digit, from the model's state when the solver
was made, however many calls came before (including failed ones); a load case (``force``) must
give what spacar.static gives on a model with those FORCE loads; the model is never changed.

The models cover the paths of the static analysis: an open chain of PLBEAMs (recognized and
solved element by element), a spatial BEAM cantilever with a follower torque and gravity (LAMBDA
nodes), coordinates as DOFs with released deformations and an input, the von Mises truss (a
general closed system) by load steps and past its limit point by the arc-length method, and a
drive that moves an input through a spring.
"""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from support.spatial_models import cantilever as beam_cantilever
from test_statics import _tangent_models, plbeam_cantilever, von_mises_truss  # tests/core/test_statics.py
from test_statics_arc_length import truss_pushed_through_a_spring  # tests/core/test_statics_arc_length.py

ARRAYS = ("t", "x", "e", "sigma", "reaction")
STATS = ("iterations", "newton_iterations", "step_cuts", "kinematic_iterations", "indefinite_at", "limit_points",
         "load_reached")


def cases():
    tangent = _tangent_models()
    return {
        "PLBEAM chain": (plbeam_cantilever(12, force=(0.5, 3.0), moment=0.4), dict(steps=2)),
        "spatial TORQUEL": (tangent["spatial TORQUEL"], dict(steps=3)),
        "planar DYNX RLSE input": (tangent["planar DYNX RLSE"], dict(steps=2)),
        "von Mises truss": (von_mises_truss(2e-4), dict(steps=4)),
        "von Mises arc length": (von_mises_truss(0.05), dict(steps=10, arc_length=True)),
        "drive through a spring": (truss_pushed_through_a_spring(0.3, 0.3), dict(steps=20, arc_length=True)),
    }


def assert_same(a, b):
    for key in ARRAYS:
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key), err_msg=key)
    for key in STATS:
        assert a.stats[key] == b.stats[key], key


@pytest.mark.parametrize("name", list(cases()))
def test_every_call_gives_static_to_the_last_digit(name):
    model, options = cases()[name]
    positions = lambda m: np.concatenate([n.x for n in m.nodes.values()])  # noqa: E731
    before, snapshot = positions(model), model.copy()
    solver = spacar.StaticSolver(model)
    reference = spacar.static(snapshot, **options)
    for _ in range(3):
        assert_same(solver(**options), reference)
    # The model is not changed by the solver (spacar.static moved its copy to the equilibrium).
    np.testing.assert_array_equal(positions(model), before)
    assert not np.array_equal(positions(snapshot), before)


def test_a_load_case_is_the_model_with_those_loads():
    n = 10
    solver = spacar.StaticSolver(plbeam_cantilever(n, force=(0.0, 3.0)))
    f = solver.force
    tip = solver.coordinate(2 * n + 1, 2)
    assert f[tip] == 3.0 and np.count_nonzero(f) == 1
    f[solver.coordinate(2 * n + 1, 1)] = -1.0
    f[tip] = 0.1                              # the model's 3 replaced (not 3 + (0.1 − 3))
    f[solver.coordinate(2 * n + 2, 1)] = 0.7  # a moment on the tip's BETA node
    f[solver.coordinate(n + 1, 2)] = 2.0      # a load on the middle node
    res = solver(f, steps=3)
    loaded = plbeam_cantilever(n, force=(-1.0, 0.1), moment=0.7)
    loaded.force(n + 1, 0.0, 2.0)
    reference = spacar.static(loaded, steps=3)
    assert_same(res, reference)
    # The model's loads again, after the load case.
    assert_same(solver(steps=3), spacar.static(plbeam_cantilever(n, force=(0.0, 3.0)), steps=3))
    # The compliance of a load case's results takes that case's loads (its geometric stiffness).
    np.testing.assert_allclose(spacar.compliance(res, 2 * n + 1), spacar.compliance(reference, 2 * n + 1),
                               rtol=1e-11, atol=0)


def test_after_a_failed_call_the_next_starts_afresh():
    h = 0.1
    solver = spacar.StaticSolver(von_mises_truss(0.0, h))
    labels = solver.coordinate_labels
    assert labels.shape == (6, 2) and tuple(labels[-1]) == (3, 2)
    beyond = solver.force
    beyond[solver.coordinate(3, 2)] = -5e-4  # beyond the limit load (3.8e-4 for h = 0.1)
    with pytest.raises(spacar.StaticError) as info:
        solver(beyond, steps=4)
    assert len(info.value.results.t) < 4
    below = solver.force
    below[solver.coordinate(3, 2)] = -2e-4
    assert_same(solver(below, steps=4), spacar.static(von_mises_truss(2e-4, h), steps=4))


def test_spatial_load_case_and_results():
    m = beam_cantilever(6, EIy=1.0, EIz=1.0, GIp=1.0, rhoA=0.0)
    solver = spacar.StaticSolver(m)
    f = solver.force
    f[solver.coordinate(7, 2)] = 1.5
    res = solver(f, steps=4)
    loaded = beam_cantilever(6, EIy=1.0, EIz=1.0, GIp=1.0, rhoA=0.0)
    loaded.force(7, 0.0, 1.5, 0.0)
    assert_same(res, spacar.static(loaded, steps=4))
    assert res.node(7).x[-1][1] > 0.3
    assert res.geometry.elements[0].type == "BEAM"  # the solver's model, shared


def test_bad_input():
    with pytest.raises(spacar.InputError, match="spacar.Model"):
        spacar.StaticSolver("model")
    solver = spacar.StaticSolver(plbeam_cantilever(2, force=(0.0, 1.0)))
    with pytest.raises(spacar.InputError, match="one value per nodal coordinate"):
        solver(np.zeros(3))
    with pytest.raises(spacar.InputError, match="finite"):
        solver(np.full(len(solver.force), np.nan))
    with pytest.raises(spacar.InputError, match="numbers"):
        solver(["a"] * len(solver.force))
    with pytest.raises(spacar.InputError, match="numbers"):
        solver([10**400] * len(solver.force))
    with pytest.raises(spacar.InputError, match="steps"):
        solver(steps=0)
    with pytest.raises(spacar.InputError, match="no coordinate 3 of node 5"):
        solver.coordinate(5, 3)
    assert "nodal coordinates" in repr(solver)


def test_a_call_stopped_by_its_time_limit_keeps_its_steps_and_the_next_starts_afresh():
    solver = spacar.StaticSolver(plbeam_cantilever(3, force=(0.0, 1e-3)))
    with pytest.raises(spacar.TimeLimitError, match=r"\(in the static analysis\)") as err:
        solver(steps=10**6, time_limit=0.2)   # several seconds of load steps
    assert 0 < len(err.value.results.t) < 10**6
    assert_same(solver(steps=2), spacar.static(plbeam_cantilever(3, force=(0.0, 1e-3)), steps=2))
