"""Static compliance at a node (issue 19, spacar.compliance) against beam theory computed here:
the planar cantilever's tip compliance [[L/EA, 0, 0], [0, L³/3EI, L²/2EI], [0, L²/2EI, L/EI]]
(exact for the cubic Hermite beams), the spatial one's 6 × 6 in global axes, a parallel
leaf-spring guide's drive stiffness 24 EI/L³; and at a large-deflection equilibrium against
central differences of static solutions (the geometric stiffness of the load included).
"""
from __future__ import annotations

import pickle

import numpy as np
import pytest

import spacar
from spacar.errors import InputError, StaticError
from support.spatial_models import cantilever as beam_cantilever


def planar_cantilever(n, L, EA, EI, rigid_axis=False, force=None):
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k * L / n, 0.0)
        m.estiff(k, EA, EI)
        m.dyne(k, 2, 3) if rigid_axis else m.dyne(k, 1, 2, 3)
    m.fix(1)
    m.fix(2)
    if force is not None:
        m.force(2 * n + 1, *force[:2])
        if len(force) > 2:
            m.force(2 * n + 2, force[2])
    return m


def test_planar_cantilever_tip_compliance():
    n, L, EA, EI = 4, 2.0, 300.0, 5.0
    C = spacar.compliance(planar_cantilever(n, L, EA, EI), 2 * n + 1, rotation=2 * n + 2)
    expected = np.array([[L / EA, 0, 0], [0, L**3 / (3 * EI), L**2 / (2 * EI)], [0, L**2 / (2 * EI), L / EI]])
    np.testing.assert_allclose(C, expected, atol=1e-12 * expected.max())
    # The position alone, the rotation alone, a node halfway.
    np.testing.assert_allclose(spacar.compliance(planar_cantilever(n, L, EA, EI), 2 * n + 1), expected[:2, :2],
                               atol=1e-12)
    np.testing.assert_allclose(spacar.compliance(planar_cantilever(n, L, EA, EI), 2 * n + 2), [[L / EI]], rtol=1e-12)
    a = L / 2
    mid = spacar.compliance(planar_cantilever(n, L, EA, EI), n + 1)
    assert mid[1, 1] == pytest.approx(a**3 / (3 * EI), rel=1e-12)
    # A supported node does not move.
    np.testing.assert_allclose(spacar.compliance(planar_cantilever(n, L, EA, EI), 1), 0.0, atol=1e-15)


def test_spatial_cantilever_6x6():
    n, L, EA, GJ, EIy, EIz = 3, 1.5, 10.0, 1.0, 2.0, 4.0
    m = beam_cantilever(n, L=L)
    for e in range(1, n + 1):
        m.dyne(e, 1)
        m.estiff(e, EA, GJ, EIy, EIz)
    C = spacar.compliance(m, n + 1, rotation=101 + n)
    expected = np.zeros((6, 6))
    expected[0, 0] = L / EA
    expected[1, 1], expected[1, 5] = L**3 / (3 * EIz), L**2 / (2 * EIz)     # Fy: y and θz
    expected[2, 2], expected[2, 4] = L**3 / (3 * EIy), -L**2 / (2 * EIy)    # Fz: z and −θy
    expected[3, 3], expected[4, 4], expected[5, 5] = L / GJ, L / EIy, L / EIz
    expected = np.triu(expected) + np.triu(expected, 1).T
    np.testing.assert_allclose(C, expected, atol=1e-10 * np.abs(expected).max())


def parallel_leaf_guide(L, d, EI):
    """Two vertical leaves (nodes 1–4 and 5–8) clamped at the base, their tops joined by a rigid
    stage (element 3); axially rigid; the stage's x (node 3) the degree of freedom."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 5, 6, 7, 8)
    m.plbeam(3, 3, 4, 7, 8)
    m.x(1, 0.0, 0.0)
    m.x(3, 0.0, L)
    m.x(5, d, 0.0)
    m.x(7, d, L)
    for n in (1, 2, 5, 6):
        m.fix(n)
    m.dynx(3, 1)
    for e in (1, 2):
        m.rlse(e, 2, 3)
        m.estiff(e, 0.0, EI)
    return m


def test_parallel_leaf_spring_drive_stiffness():
    L, d, EI = 0.05, 0.03, 0.35
    C = spacar.compliance(parallel_leaf_guide(L, d, EI), 3, rotation=4)
    assert 1.0 / C[0, 0] == pytest.approx(24 * EI / L**3, rel=1e-10)
    np.testing.assert_allclose(C[1:, :], 0.0, atol=1e-12 * C[0, 0])  # guided: no y, no rotation


def test_compliance_at_a_large_deflection_is_the_derivative_of_the_static_solution():
    n, P = 10, 3.0  # P L²/EI = 3: a large deflection; the geometric stiffness matters
    loaded = planar_cantilever(n, 1.0, 1e3, 1.0, force=(0.0, P))
    spacar.static(loaded, steps=4)
    C = spacar.compliance(loaded, 2 * n + 1, rotation=2 * n + 2)
    h = 1e-4
    for j, dload in enumerate(np.eye(3) * h):
        tips = [spacar.static(planar_cantilever(n, 1.0, 1e3, 1.0, force=(0.0, P, 0.0) + s * dload), steps=4).x[-1, -3:]
                for s in (1, -1)]
        np.testing.assert_allclose((tips[0] - tips[1]) / (2 * h), C[:, j], rtol=2e-6, atol=2e-6)
    # Stiffer than the small-deflection cantilever in y: the deflected beam carries the load partly axially.
    assert C[1, 1] < 1 / 3


def test_mechanism_and_bad_nodes():
    m = planar_cantilever(2, 1.0, 1.0, 1.0)
    m.estiff(2, 1.0, 0.0)  # the second element has no bending stiffness: a mechanism
    with pytest.raises(StaticError, match="singular.*DYNE element 2"):
        spacar.compliance(m, 5)
    ok = planar_cantilever(2, 1.0, 1.0, 1.0)
    with pytest.raises(InputError, match="not a node"):
        spacar.compliance(ok, 99)
    with pytest.raises(InputError, match="BETA or LAMBDA"):
        spacar.compliance(ok, 5, rotation=5)
    with pytest.raises(InputError, match="spacar.Model"):
        spacar.compliance("model", 5)


# ------------------------------------------------------------------------------------------------
# support stiffness
# ------------------------------------------------------------------------------------------------

def test_propped_and_guided_cantilever_support_stiffness():
    n, L, EI = 3, 1.5, 2.0
    propped = planar_cantilever(n, L, 0.0, EI, rigid_axis=True)
    propped.fix(2 * n + 1, 2)   # the tip's y supported
    K = spacar.support_stiffness(propped, 2 * n + 1)
    np.testing.assert_allclose(K, [[3 * EI / L**3]], rtol=1e-10)
    assert [c.name for c in propped.nodes[2 * n + 1].cls] == ["calculable", "fixed"]  # the model is not changed
    guided = planar_cantilever(n, L, 0.0, EI, rigid_axis=True)
    guided.fix(2 * n + 1, 2)
    guided.fix(2 * n + 2)       # and its rotation
    K = spacar.support_stiffness(guided, 2 * n + 1)
    np.testing.assert_allclose(K, [[12 * EI / L**3]], rtol=1e-10)  # y, the rotation held
    K = spacar.support_stiffness(guided, 2 * n + 2)
    np.testing.assert_allclose(K, [[4 * EI / L]], rtol=1e-10)      # β, y held


def test_driven_parallel_leaf_guide_drive_stiffness():
    L, d, EI = 0.05, 0.03, 0.35
    m = parallel_leaf_guide(L, d, EI)
    m.apply("INPUTX", 3, 1)     # the stage driven in x instead of free
    assert spacar.support_stiffness(m, 3, 1)[0, 0] == pytest.approx(24 * EI / L**3, rel=1e-10)
    with pytest.raises(InputError, match="prescribed"):
        spacar.support_stiffness(m, 3, 2)  # y is calculable


def test_compliance_along_a_static_load_path():
    n, P = 8, 3.0
    model = planar_cantilever(n, 1.0, 1e3, 1.0, force=(0.0, P))
    res = spacar.static(model, steps=4)
    along = [spacar.compliance(model, 2 * n + 1, results=res, k=k) for k in range(4)]
    np.testing.assert_allclose(along[-1], spacar.compliance(model, 2 * n + 1), rtol=1e-12, atol=1e-15)
    half = planar_cantilever(n, 1.0, 1e3, 1.0, force=(0.0, P / 2))
    spacar.static(half, steps=2)
    np.testing.assert_allclose(along[1], spacar.compliance(half, 2 * n + 1), rtol=1e-7, atol=1e-12)
    assert along[0][1, 1] > along[1][1, 1] > along[3][1, 1]  # the elastica stiffens with the load
    with pytest.raises(InputError, match="spacar.static"):
        spacar.compliance(model, 2 * n + 1, results=object())


def test_static_results_carry_their_model():
    n, P = 8, 3.0
    model = planar_cantilever(n, 1.0, 1e3, 1.0, force=(0.0, P))
    res = spacar.static(model, steps=4)
    model.force(2 * n + 1, 0.0, 10 * P)   # changing the model afterwards does not change the results' copy
    for k in (1, -1):
        expected = spacar.compliance(planar_cantilever(n, 1.0, 1e3, 1.0, force=(0.0, P)), 2 * n + 1,
                                     results=res, k=k)
        np.testing.assert_allclose(spacar.compliance(res, 2 * n + 1, k=k), expected, rtol=1e-12, atol=1e-15)
    with pytest.raises(InputError, match="once"):
        spacar.compliance(res, 2 * n + 1, results=res)
    loaded = pickle.loads(pickle.dumps(res))
    with pytest.raises(InputError, match="do not carry their model"):
        spacar.compliance(loaded, 2 * n + 1)
