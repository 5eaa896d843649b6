"""spacar.inverse_dynamics on planar and spatial trees of rigid bodies (the recursive Newton–Euler
algorithm of cpp/include/spacar/recursive/articulated.hpp) against the general path's reduced
equations, M̄ (q̈ − q̈₀) from its own mass matrix and accelerations at the same state (an
independent computation: transfer functions, no recursion), with hinge springs and dampers,
absolute rotations as DOFs (DYNX BETA), applied forces and gravity; and at the forward dynamics'
accelerations the forces vanish. (Against pinocchio.rnea: tests/api/test_urdf.py.)"""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import InputError, _core
from spacar.compare import models
from support import trees
from support.paths import DATA, EXAMPLES

MODELS = {
    "planar branched tree, springs": lambda: trees.planar_branched_tree(spring=False),
    "planar chain, absolute rotations, springs": lambda: models.planar_chain(
        4, dof="absolute", stiffness=3.0, damping=0.4, tip_mass=0.3, joint_inertia=0.01, angle=0.3),
    "planar chain, relative angles": lambda: models.planar_chain(5, tip_mass=0.2, angle=-0.4),
    "spatial branched tree": lambda: trees.spatial_branched_tree(),
    "spatial chain": lambda: models.spatial_chain(6, seed=3),
    "spatial URDF wrist (joints at one origin, a sliding joint, a body without a beam)":
        lambda: trees.urdf(DATA / "wrist.urdf"),
    "spatial random tree": lambda: trees.random_tree(7, 2),
    "spatial sliding joints, forces below them, TORQUEL, a spring-damper, oblique gravity":
        lambda: loaded_prismatic(),
    "spatial branched tree, initial hinge angles": lambda: turned_branched_tree(),
}


# Closed loops on the recursive path (closed_loop.hpp): Tᵀ τ_id(θ, θ̇, T q̈ + g) in the tree's
# coordinates with the loop closed.
LOOPS = {
    "spatial RSUR loop (a ball joint closes it)": trees.rsur,
    "spatial RSUR loop from a URDF, a spring on a dependent joint": lambda: sprung(trees.urdf_rsur()),
    "spatial 7R loop (closed at a point and a cut hinge)": trees.seven_bar,
    "spatial 7R loop cut between two moving links": lambda: trees.seven_bar(last=4),
    "planar four-bar (passive rotations of the coupler and rocker)": lambda: models.four_bar(),
    "planar four-bar, a DYNE PLHINGE crank, springs, a damper, FORCE": trees.hinged_four_bar,
}


def sprung(model):
    model.estiff(2, 0.8)  # the rocker's hinge: a released rotation with a spring
    model.edampp(2, 0.1)
    return model


def loaded_prismatic():
    """tests/data/prismatic.urdf (a carriage sliding on the ground, an arm, a finger sliding on it)
    with FORCEs on the finger (two) and the arm (two) below the sliding joints, TORQUELs, a spring
    and damper on the first joint and gravity off the axes."""
    m = trees.urdf(DATA / "prismatic.urdf")
    for node, f in ((17, (0.3, -0.5, 0.7)), (12, (-0.2, 0.4, 0.1)), (15, (0.6, 0.2, -0.3)), (10, (0.1, 0.1, 0.9)),
                    (13, (-0.4, 0.3, 0.2))):
        m.force(node, *f)
    m.torquel(9, 0.1, -0.2, 0.3)
    m.torquel(6, -0.3, 0.1, 0.2)
    m.estiff(2, 1.5)
    m.edampp(2, 0.2)
    m.gravity(2.0, -3.0, -8.0)
    return m


def turned_branched_tree():
    """The spatial branched tree with its hinges turned at the start (E: joint angles offset from
    the reference geometry)."""
    m = trees.spatial_branched_tree()
    for hinge, angle in zip((101, 102, 103, 104), (0.4, -0.7, 0.9, 0.3)):
        m.e(hinge, 1, angle)
    return m


def general_path(model, q, qd, qdd):
    """M̄ (q̈ − q̈₀) by the general path, state by state from the assembled one."""
    sim = _core.Simulation(model.core)
    sim.assemble()
    out = []
    for k in range(len(q)):
        sim.evaluate(0.0, q[k], qd[k])
        out.append(np.asarray(sim.data.Mbar) @ (qdd[k] - np.asarray(sim.data.qdd)))
    return np.array(out)


@pytest.mark.parametrize("name", list(MODELS) + list(LOOPS))
def test_recursive_inverse_dynamics_matches_the_reduced_equations(name):
    model = MODELS[name]() if name in MODELS else LOOPS[name]()
    sim = _core.Simulation(model.copy().core)
    sim.assemble()
    n = sim.system.n_dof
    q0 = np.asarray(sim.system.q0)
    rng = np.random.default_rng(7)
    q = q0 + np.outer(np.linspace(0.0, 1.0, 12), rng.uniform(-1.0, 1.0, n))  # steps of at most 0.1
    qd, qdd = rng.uniform(-2.0, 2.0, (12, n)), rng.uniform(-3.0, 3.0, (12, n))
    force, path = sim.inverse_dynamics(q, qd, qdd)
    assert path == "tree"
    ref = general_path(model.copy(), q, qd, qdd)
    scale = max(1.0, np.abs(ref).max())
    assert np.abs(np.asarray(force) - ref).max() <= 1e-10 * scale
    # At the forward dynamics' accelerations (the tree's ABA) nothing more is needed.
    free = np.array([sim.recursive_state(q[k], qd[k])["qdd"] for k in range(len(q))])
    zero, _ = sim.inverse_dynamics(q, qd, free)
    assert np.abs(np.asarray(zero)).max() <= 1e-10 * scale


def test_other_systems_take_the_reduced_equations():
    # A flexible cantilever is no tree of rigid bodies: its DOFs' forces are M̄ (q̈ − q̈₀).
    model = models.cantilever(2)
    sim = _core.Simulation(model.copy().core)
    sim.assemble()
    n = sim.system.n_dof
    q, qd, qdd = np.asarray(sim.system.q0)[None, :], np.full((1, n), 0.7), np.full((1, n), 1.3)
    force, path = sim.inverse_dynamics(q, qd, qdd)
    assert path == "general"
    np.testing.assert_allclose(force, general_path(model.copy(), q, qd, qdd), rtol=1e-12, atol=1e-14)
    assert spacar.inverse_dynamics(model, q[0], qd[0], qdd[0]).shape == (n,)


DERIVATIVE_LOOPS = {
    "four-bar, DYNX crank": models.four_bar,
    "four-bar, DYNE PLHINGE crank, springs, damper, FORCE": trees.hinged_four_bar,
    "four-bar, reversed DYNE PLHINGE, a sprung and damped released hinge": trees.reversed_hinged_four_bar,
    "four-bar driven between crank and coupler": trees.four_bar_driven_between_links,
    "four-bar driven at the rocker": trees.rocker_driven_four_bar,
    "five-bar, 2 DOFs": trees.five_bar,
    "six-bar, two loops": trees.six_bar,
    "spatial RSUR, closed at a point": trees.rsur,
    "spatial RSUR from a URDF, closed by a ball joint": trees.urdf_rsur,
    "spatial RSUP (a sliding passive joint) with a pendulum, 2 DOFs, springs and loads": trees.urdf_rsup_pendulum,
    "spatial 7R loop, closed at a point and a cut hinge": trees.seven_bar,
    "spatial 7R loop driven in the middle, cut elsewhere": lambda: trees.seven_bar(dof=4),
    "spatial 7R loop cut between two moving links": lambda: trees.seven_bar(last=4),
}


def double_path_accelerations(sim, dyn, q, qd, tau):
    """q̈ under τ without the dual numbers: the forward dynamics of a run's right-hand side (τ = 0,
    ClosedLoopTree::solve) plus M⁻¹ τ, M from the loops' inverse dynamics (affine in q̈)."""
    n = len(q)
    rest = dyn.inverse_dynamics(q, np.zeros(n), np.zeros(n))
    M = np.column_stack([dyn.inverse_dynamics(q, np.zeros(n), e) - rest for e in np.eye(n)])
    return sim.recursive_state(q, qd)["qdd"] + np.linalg.solve(M, tau)


@pytest.mark.parametrize("offset", [0.0, 0.3])
@pytest.mark.parametrize("name", DERIVATIVE_LOOPS)
def test_closed_loops_have_exact_derivatives(name, offset):
    """spacar.dynamics_derivatives on planar and spatial loops closed at points and at cut hinges
    (their misalignments written on the dual numbers from the hinge frame; the loops' forward
    dynamics on dual numbers, closed_loop.cpp, with the tree's inverse dynamics of planar_rnea.hpp
    and spatial_rnea.hpp): its q̈ under τ gives back τ through spacar.inverse_dynamics (the
    loops' double recursion, checked above against the reduced equations) and equals the double
    path's forward dynamics; ∂q̈/∂τ is the inverse of the mass matrix that inverse_dynamics implies;
    ∂q̈/∂q, ∂q̈/∂q̇ equal central differences of the double path's q̈ to 1e-7. At a state near the
    assembled one and one 0.3 rad further (reached by continuation)."""
    model = DERIVATIVE_LOOPS[name]()
    sim = _core.Simulation(model.copy().core)
    sim.assemble()
    dyn = spacar.Dynamics(model)
    rng = np.random.default_rng(7)
    n = sim.system.n_dof
    q = np.array(sim.system.q0) + offset + rng.uniform(-0.05, 0.05, n)
    qd, tau = rng.uniform(-1.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
    qdd, dq, dqd, dtau = dyn.dynamics_derivatives(q, qd, tau)
    scale = max(1.0, np.abs(tau).max(), np.abs(dyn.inverse_dynamics(q, qd, np.zeros(n))).max())
    assert np.abs(dyn.inverse_dynamics(q, qd, qdd) - tau).max() <= 1e-11 * scale
    np.testing.assert_allclose(qdd, double_path_accelerations(sim, dyn, q, qd, tau), rtol=1e-10, atol=1e-10)
    rest = dyn.inverse_dynamics(q, np.zeros(n), np.zeros(n))
    M = np.column_stack([dyn.inverse_dynamics(q, np.zeros(n), e) - rest for e in np.eye(n)])
    assert np.abs(dtau @ M - np.eye(n)).max() <= 1e-10
    h = 1e-5  # the loops are closed to 1e-14: differences over 1e-6 carry 1e-8 of that noise
    for j in range(n):
        e = h * np.eye(n)[j]
        fd_q = (double_path_accelerations(sim, dyn, q + e, qd, tau)
                - double_path_accelerations(sim, dyn, q - e, qd, tau)) / (2 * h)
        fd_qd = (double_path_accelerations(sim, dyn, q, qd + e, tau)
                 - double_path_accelerations(sim, dyn, q, qd - e, tau)) / (2 * h)
        assert np.abs(dq[:, j] - fd_q).max() <= 1e-7 * max(1.0, np.abs(dq).max())
        assert np.abs(dqd[:, j] - fd_qd).max() <= 1e-7 * max(1.0, np.abs(dqd).max())
    # A batch: one call, each state's own derivatives.
    batch = dyn.dynamics_derivatives(np.array([q, q + 0.01]), np.array([qd, -qd]), np.array([tau, tau]))
    np.testing.assert_allclose(batch[1][0], dq, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(batch[1][1], dyn.dynamics_derivatives(q + 0.01, -qd, tau)[1], rtol=1e-10, atol=1e-10)


def test_bad_arguments_are_input_errors():
    model = models.planar_chain(2)
    with pytest.raises(InputError, match="same shape"):
        spacar.inverse_dynamics(model, np.zeros(2), np.zeros(2), np.zeros(3))
    with pytest.raises(InputError, match="one column per degree of freedom"):
        spacar.inverse_dynamics(model, np.zeros(3), np.zeros(3), np.zeros(3))
    with pytest.raises(InputError, match="finite"):
        spacar.inverse_dynamics(model, [np.nan, 0.0], np.zeros(2), np.zeros(2))
    dyn = spacar.Dynamics(model)  # the finiteness checked in the core
    with pytest.raises(InputError, match="inverse_dynamics: qdd must be finite"):
        dyn.inverse_dynamics(np.zeros(2), np.zeros(2), [0.0, np.inf])
    with pytest.raises(InputError, match="dynamics_derivatives: q must be finite"):
        dyn.dynamics_derivatives(np.array([[0.0, 0.0], [np.nan, 0.0]]), np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(InputError, match="spacar.Model"):
        spacar.inverse_dynamics("model", np.zeros(2), np.zeros(2), np.zeros(2))


@pytest.mark.parametrize("name", list(MODELS) + ["planar branched tree, a spring between the branches"])
def test_dynamics_derivatives_agree_with_the_inverse_dynamics_and_differences(name):
    """spacar.dynamics_derivatives (analytic on spatial trees, spatial_derivatives.cpp; the
    recursive Newton–Euler algorithm on dual numbers on planar ones, planar_rnea.hpp) on every
    tree above: its q̈ under τ gives back τ through
    spacar.inverse_dynamics (the double recursion of articulated.hpp, checked above against the
    reduced equations), ∂q̈/∂τ is the inverse of the mass matrix that inverse_dynamics implies,
    and ∂q̈/∂q, ∂q̈/∂q̇ equal central differences of q̈ to 1e-6."""
    model = MODELS[name]() if name in MODELS else trees.planar_branched_tree(spring=True)
    sim = _core.Simulation(model.core)
    sim.assemble()
    rng = np.random.default_rng(5)
    n = sim.system.n_dof
    q = np.array(sim.system.q0) + rng.uniform(-0.3, 0.3, n)
    qd, tau = rng.uniform(-1.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
    qdd, dq, dqd, dtau = spacar.dynamics_derivatives(model, q, qd, tau)
    scale = max(1.0, np.abs(tau).max(), np.abs(spacar.inverse_dynamics(model, q, qd, np.zeros(n))).max())
    assert np.abs(spacar.inverse_dynamics(model, q, qd, qdd) - tau).max() <= 1e-10 * scale
    rest = spacar.inverse_dynamics(model, q, np.zeros(n), np.zeros(n))
    M = np.column_stack([spacar.inverse_dynamics(model, q, np.zeros(n), e) - rest for e in np.eye(n)])
    assert np.abs(dtau @ M - np.eye(n)).max() <= 1e-9
    h = 1e-6
    for j in range(n):
        e = h * np.eye(n)[j]
        fd_q = (spacar.dynamics_derivatives(model, q + e, qd, tau)[0]
                - spacar.dynamics_derivatives(model, q - e, qd, tau)[0]) / (2 * h)
        fd_qd = (spacar.dynamics_derivatives(model, q, qd + e, tau)[0]
                 - spacar.dynamics_derivatives(model, q, qd - e, tau)[0]) / (2 * h)
        assert np.abs(dq[:, j] - fd_q).max() <= 1e-6 * max(1.0, np.abs(dq).max())
        assert np.abs(dqd[:, j] - fd_qd).max() <= 1e-6 * max(1.0, np.abs(dqd).max())


@pytest.mark.parametrize("name", ["spatial chain", "planar chain, absolute rotations, springs"])
def test_a_dynamics_handle_equals_the_functions(name):
    """spacar.Dynamics (set up once) gives the functions' numbers, call after call, on a copy of
    the model (a later change of the model is not seen)."""
    model = MODELS[name]()
    dyn = spacar.Dynamics(model)
    assert dyn.path == "tree"
    rng = np.random.default_rng(4)
    n = dyn.n_dof
    q, qd, qdd = (rng.uniform(-1.0, 1.0, (3, n)) for _ in range(3))
    tau = spacar.inverse_dynamics(model, q, qd, qdd)
    for _ in range(2):
        assert np.array_equal(dyn.inverse_dynamics(q, qd, qdd), tau)
        for ours, theirs in zip(dyn.dynamics_derivatives(q, qd, tau), spacar.dynamics_derivatives(model, q, qd, tau)):
            assert np.array_equal(ours, theirs)
    np.testing.assert_allclose(dyn.dynamics_derivatives(q[0], qd[0], tau[0])[0], qdd[0], rtol=0, atol=1e-10)
    # Arrays of any layout (passed to the core without a contiguous copy): a Fortran-ordered batch,
    # a strided vector.
    assert np.array_equal(dyn.inverse_dynamics(np.asfortranarray(q), qd, qdd), tau)
    wide = np.repeat(q[1], 2)[::2]
    assert not wide.flags.c_contiguous
    assert np.array_equal(dyn.inverse_dynamics(wide, qd[1], qdd[1]), tau[1])
    model.gravity(*([0.0] * (3 if "spatial" in name else 2)))
    assert np.array_equal(dyn.inverse_dynamics(q, qd, qdd), tau)
    assert len(dyn.dof_labels) == n


def test_a_dynamics_handle_on_the_general_path_forgets_its_calls():
    """On the general path each call starts Newton's iterations from the assembled positions: a
    call's forces do not depend on the calls before it."""
    model = spacar.read(EXAMPLES / "slidercrank.dat")
    dyn = spacar.Dynamics(model)
    assert dyn.path == "general"
    n = dyn.n_dof
    q = np.linspace(0.0, 1e-3, 3 * n).reshape(3, n)
    qd = np.zeros((3, n))
    qdd = np.ones((3, n))
    first = dyn.inverse_dynamics(q[2], qd[2], qdd[2])
    dyn.inverse_dynamics(q, qd, qdd)
    assert np.array_equal(dyn.inverse_dynamics(q[2], qd[2], qdd[2]), first)
    np.testing.assert_allclose(first, spacar.inverse_dynamics(model, q[2], qd[2], qdd[2]), rtol=1e-9, atol=1e-12)
