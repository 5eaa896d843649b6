"""The saddle-point system of the nodal coordinates (cpp/src/analyses/nodal.cpp, docs/formulation.md §10), on
which the static solve, the compliance and the sparse eigen-analyses stand: its solution for a
load r on the coordinates must be δx = DF_q K⁻¹ DF_qᵀ r with the dense reduced tangent
K = K0 + G0 (itself checked against differences of the residual in test_statics.py), its
determinant's sign that of K, its count of negative eigenvalues that of K's (Sylvester), and a
singular K must be found singular. Planar and spatial models, rigid constraints (L2MIN1, rigid
beams, hinges), inputs, gravity on beams and unsymmetric follower torques (TORQUEL)."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import _core, _testing
from support.paths import EXAMPLES
from support.planar_models import compressed_cantilever
from support.spatial_models import cantilever as beam_cantilever


def _models():
    spatial = beam_cantilever(5, EIy=2.0, EIz=1.0, GIp=0.7, rhoA=0.3)
    spatial.force(6, 0.2, -0.3, 0.4)
    spatial.torquel(106, 0.1, -0.2, 0.3)
    spatial.gravity(0.0, 0.0, -1.0)
    gravity = compressed_cantilever(6)
    gravity.gravity(0.3, -2.0)
    return {
        "planar cantilever, gravity": gravity,
        "spatial beams, TORQUEL": spatial,
        "parallel leaf guide": spacar.read(EXAMPLES / "parallel_leaf_guide.dat"),
        "cross spring pivot": spacar.read(EXAMPLES / "cross_spring_pivot.dat"),
        "slider-crank (flexible coupler)": spacar.read(EXAMPLES / "slidercrank.dat"),
        "spatial slider-crank": spacar.read(EXAMPLES / "slidercrank3d.dat"),
    }


def _at(model, load_factor=1.0):
    """The assembled simulation, with the dense reduced tangent (static_forces) and DF there."""
    model.prepare()
    sim = _core.Simulation(model.core)
    sim.assemble()
    R, K = _testing.static_forces(sim, load_factor)
    DFq = np.array(sim.data.DF)[:, list(sim.system.dof_cols)]
    return sim, np.array(K), DFq


@pytest.mark.parametrize("name", list(_models()))
def test_solution_is_the_reduced_one(name):
    sim, K, DFq = _at(_models()[name])
    nx = sim.system.nx
    if np.linalg.cond(K) > 1e10:
        pytest.skip("the reduced tangent of this state is (nearly) singular")
    rng = np.random.default_rng(3)
    r = rng.standard_normal((nx, 3))
    d = _testing.nodal_solve(sim, 1.0, r)
    assert d["ok"] and not d["singular"]
    expected = DFq @ np.linalg.solve(K, DFq.T @ r)
    assert np.abs(d["dx"] - expected).max() <= 1e-9 * np.abs(expected).max()
    # The reduced coordinates of the solution: δq = E δx.
    np.testing.assert_allclose(d["E"] @ d["dx"], np.linalg.solve(K, DFq.T @ r), rtol=1e-8,
                               atol=1e-9 * np.abs(expected).max())
    assert d["sign"] == np.sign(np.linalg.det(K))
    symmetric = np.abs(K - K.T).max() <= 1e-9 * np.abs(K).max()
    assert d["symmetric"] == symmetric or not d["symmetric"]  # TORQUEL: handled as unsymmetric
    if d["symmetric"]:
        assert d["negative"] == int((np.linalg.eigvalsh(0.5 * (K + K.T)) < 0).sum())
    else:
        assert d["negative"] == -1


@pytest.mark.parametrize("factor, negative", [(0.5, 0), (1.5, 1), (10.0, 2)])
def test_negative_eigenvalues_of_a_compressed_column(factor, negative):
    """A cantilever column under P = factor · P_cr at its straight state: K0 + G0 has as many
    negative eigenvalues as buckling loads (π²/4, 9π²/4, ...) below P."""
    m = compressed_cantilever(8)
    m.force(17, -factor * np.pi**2 / 4 + 1.0, 0.0)  # the model's own unit load included
    sim, K, _ = _at(m)
    assert int((np.linalg.eigvalsh(0.5 * (K + K.T)) < 0).sum()) == negative
    d = _testing.nodal_solve(sim, 1.0, np.zeros((sim.system.nx, 1)))
    assert d["negative"] == negative and d["sign"] == (-1) ** negative


def test_singular_tangent_is_found():
    """A hinge DYNE without stiffness, nothing loaded: K0 + G0 is singular."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, 1.0, 0.0)
    m.plhinge(2, 4, 6)
    m.plbeam(3, 3, 6, 5, 7)
    m.x(5, 2.0, 0.0)
    m.estiff(1, 1.0, 1.0)
    m.estiff(3, 1.0, 1.0)
    m.dyne(1, 2, 3)
    m.dyne(3, 2, 3)
    m.dyne(2, 1)
    m.fix(1)
    m.fix(2)
    sim, K, _ = _at(m)
    assert np.linalg.svd(K, compute_uv=False)[-1] < 1e-12 * np.abs(K).max()
    d = _testing.nodal_solve(sim, 1.0, np.zeros((sim.system.nx, 1)))
    assert d["singular"]


@pytest.mark.parametrize("name", ["andrews_squeezer", "cross_spring_pivot", "parallel_leaf_guide"])
def test_static_results_are_equilibria_of_the_dense_tangent(name):
    """The examples that spacar.static loads (their equilibria take Newton iterations) end where a
    Newton step with the dense reduced tangent K0 + G0 (_testing.static_forces) would move the
    degrees of freedom by less than 1e-10 of their size: the sparse path's result is the dense
    path's."""
    model = spacar.read(EXAMPLES / f"{name}.dat")
    res = spacar.static(model, steps=2)
    assert res.stats["newton_iterations"] > 0
    sim = _core.Simulation(model.core)
    sim.assemble()
    R, K = (np.array(v) for v in _testing.static_forces(sim, 1.0))
    step = np.linalg.solve(K, R)
    sizes = [abs(v) for v in np.array(sim.system.q0)] + [1.0]
    assert np.abs(step).max() <= 1e-10 * max(1.0, max(sizes))
