"""The recursive path of planar rigid trees (cpp/include/spacar/recursive/tree.hpp, formulation.md §7).

Its accelerations are checked against the constraint formulation's sparse solve at random states
(the two share no code beyond the element mass matrices) and against Pinocchio's ABA; runs on
both paths give the same motion and output; every model that is not a planar tree of rigid bodies
takes the general path. The pendulum periods of test_planar_dynamics.py (elliptic integrals) and
the chain trajectories of test_compare.py (exudyn, Pinocchio) run on this path as well.
"""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar.compare import models
from support.simulation import assembled, assert_start_rows_agree

G = 9.81


def branched_tree(spring=False):
    """A trunk hinged to the ground, two branches hinged at its tip (one hinge points from the
    child to the parent), one branch two beams rigidly joined at a shared BETA node; masses on XY
    and BETA nodes, FORCE on points and a rotation, a hinge spring-damper, gravity with an x
    component; ``spring``: a released hinge with stiffness and damping between the branches."""
    m = spacar.Model()
    for node, xy in {1: (0, 0), 2: (1, 0.2), 3: (1.8, 0.9), 4: (1.6, -0.7), 5: (2.4, -0.5)}.items():
        m.x(node, *xy)
    m.plbeam(1, 1, 11, 2, 12)
    m.plbeam(2, 2, 21, 3, 22)
    m.plbeam(3, 2, 31, 4, 32)
    m.plbeam(4, 4, 32, 5, 42)
    m.plhinge(101, 100, 11)
    m.plhinge(102, 12, 21)
    m.plhinge(103, 31, 12)
    for h in (101, 102, 103):
        m.dyne(h, 1)
    m.fix(1)
    m.fix(100)
    for e, rho in ((1, 1.0), (2, 0.7), (3, 1.3), (4, 0.4)):
        m.emass(e, rho)
    m.mass(3, 0.2)
    m.mass(5, 0.1)
    m.mass(21, 0.05)
    m.force(3, 0.5, -0.2)
    m.force(5, 0.0, 1.0)
    m.force(31, 0.3)
    m.estiff(103, 2.0)
    m.edampp(103, 0.1)
    if spring:
        m.plhinge(104, 22, 42)
        m.rlse(104, 1)
        m.estiff(104, 1.5)
        m.edampp(104, 0.3)
    m.gravity(1.0, -G)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-12)
    m.timestep(4, 0.4)
    return m


def plbeamnl_chain():
    """Two rigid PLBEAMNL links, the second hinged by its own DYNX rotation (no PLHINGE)."""
    m = spacar.Model()
    m.x(2, 0.8, 0.3)
    m.x(3, 1.5, -0.2)
    m.plbeamnl(1, 1, 11, 2, 12)
    m.plbeamnl(2, 2, 21, 3, 22)
    m.fix(1)
    m.dynx(11, 1)
    m.dynx(21, 1)
    m.emass(1, 1.0)
    m.emass(2, 0.5)
    m.mass(3, 0.2)
    m.gravity(0.0, -G)
    m.epskin(1e-12)
    m.timestep(1, 0.1)
    return m


TREES = {
    "chain": lambda: models.planar_chain(6, rho_a=1.5, tip_mass=0.3, joint_inertia=0.02, angle=0.3),
    "chain springs": lambda: models.planar_chain(4, stiffness=3.0, damping=0.2, ground_angle=0.3, angle=-0.2),
    "chain absolute": lambda: models.planar_chain(5, dof="absolute", angle=0.3),
    "chain absolute springs": lambda: models.planar_chain(5, dof="absolute", stiffness=3.0, damping=0.2),
    "branched": branched_tree,
    "branched spring": lambda: branched_tree(spring=True),
    "PLBEAMNL, DYNX": plbeamnl_chain,
}


@pytest.mark.parametrize("name", list(TREES))
def test_output_rows_from_the_trees_accelerations_equal_the_equations_of_motion(name):
    """An output time of the recursive path takes q̈ from the tree and solves the constraints'
    stresses from the equilibrium of the calculable coordinates, without the equations of
    motion; at the start state, moving, everything it reports equals the general path's."""
    assert_start_rows_agree(TREES[name]())


@pytest.mark.parametrize("name", list(TREES))
def test_recursive_state_equals_the_constraint_formulation(name):
    """The tree is taken at the assembled state; the states compared are reached from it by the
    general path's continuation (move_to), so every joint has turned."""
    sim = assembled(TREES[name]())
    q0 = np.array(sim.system.q0)
    assert sim.recursive_state(q0, np.zeros(q0.size)) is not None  # the tree, at the assembly
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = q0 + rng.uniform(-1.0, 1.0, q0.size)
        qd = rng.uniform(-2.0, 2.0, q0.size)
        sim.move_to(0.0, q, qd)  # Newton along the path, the sparse solve of the constraint formulation
        got = sim.recursive_state(q, qd)
        d = sim.data
        for key, expected, tol in (("qdd", d.qdd, 1e-11), ("x", d.x, 1e-9), ("xd", d.xd, 1e-9), ("xdd", d.xdd, 1e-9)):
            expected = np.array(expected)
            np.testing.assert_allclose(got[key], expected, rtol=0, atol=tol * max(1.0, np.abs(expected).max()),
                                       err_msg=key)


def test_recursive_accelerations_equal_pinocchio_aba():
    pytest.importorskip("pinocchio")
    from spacar.compare import pinocchio as sp

    model = models.planar_chain(8, rho_a=1.2, tip_mass=0.1, joint_inertia=0.01, angle=0.2)
    pm = sp.build(model.copy())
    sim = assembled(model)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-1.0, 1.0, 8)
        qd = rng.uniform(-2.0, 2.0, 8)
        aba = sp.pin.aba(pm.model, pm.data, q, qd, np.zeros(8))
        np.testing.assert_allclose(sim.recursive_state(q, qd)["qdd"], aba, rtol=0, atol=1e-11 * np.abs(aba).max())


@pytest.mark.parametrize("name", ["chain springs", "chain absolute springs", "branched spring"])
def test_runs_on_both_paths_agree(name):
    model = TREES[name]()
    model.forcemode(1)
    model.epsint(1e-10)
    model.epsind(1e-10)
    model.timestep(3, 0.3)
    fast = spacar.simulate(model.copy())
    general = spacar.simulate(model.copy(), recursive=False)
    assert fast.stats["recursive"] and not general.stats["recursive"]
    assert fast.stats["newton_iterations"] < general.stats["newton_iterations"]
    for field in ("x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        a, b = getattr(fast, field), getattr(general, field)
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-7 * max(1.0, np.abs(b).max()), err_msg=field)


def held_hinge():
    """A 2-link chain whose second hinge is not a DOF (its rotation held fixed)."""
    m = models.planar_chain(1)
    m.x(3, 2.0, 0.0)
    m.plbeam(2, 2, 21, 3, 22)
    m.plhinge(9, models.END + 1, 21)
    m.emass(2, 1.0)
    return m


def position_dof():
    """A pendulum whose DOF is the x coordinate of its tip (DYNX on an XY node)."""
    m = spacar.Model()
    m.x(2, 0.6, -0.8)
    m.plbeam(1, 1, 11, 2, 12)
    m.fix(1)
    m.dynx(2, 1)
    m.emass(1, 1.0)
    m.gravity(0.0, -G)
    return m


def truss_brace():
    """A pendulum braced by a PLTRUSS (an element the recursive path does not take)."""
    m = models.planar_chain(1)
    m.x(5, 0.5, -0.5)
    m.pltruss(9, 2, 5)
    m.fix(5)
    m.rlse(9, 1)
    return m


NOT_TREES = {
    "four-bar (closed loop)": lambda: models.four_bar(),
    "hinge held fixed": held_hinge,
    "DYNX on a position": position_dof,
    "PLTRUSS": truss_brace,
    "flexible links": lambda: models.cantilever(3),
    "input-driven slider-crank": lambda: models.slider_crank(n_rod=2, t_end=0.01, n_out=1),
}


@pytest.mark.parametrize("name", list(NOT_TREES))
def test_other_models_take_the_general_path(name):
    model = NOT_TREES[name]()
    sim = assembled(model.copy())
    q0 = np.array(sim.system.q0)
    if q0.size:
        assert sim.recursive_state(q0, np.zeros(q0.size)) is None
    model.timestep(1, 1e-3)
    assert not spacar.simulate(model).stats["recursive"]


def test_a_body_without_mass_is_named_by_the_general_path():
    model = models.planar_chain(2, rho_a=0.0, tip_mass=0.0)
    sim = assembled(model.copy())
    assert sim.recursive_state(np.zeros(2), np.zeros(2)) is None
    with pytest.raises(spacar.SingularMassError, match="move no mass"):
        spacar.simulate(model)


@pytest.mark.parametrize("bad", ["no", 2, 1, 0.0, None])
def test_recursive_must_be_a_boolean(bad):
    with pytest.raises(spacar.InputError, match="recursive must be True or False"):
        spacar.simulate(models.planar_chain(2), recursive=bad)


@pytest.mark.parametrize("n_out", [2, 10])
def test_output_times_of_a_fast_spin_stay_on_the_branch(n_out):
    """A straight 2-link chain spinning at 5 rad/s without gravity turns rigidly. Its steps grow
    long (the motion is easy to integrate), so the output times are solved by Newton from the
    tree's positions at the output, not from a stage a step away: the tip stays on the circle and
    the links do not flip."""
    model = models.planar_chain(2, gravity=None, eps=1e-8, epskin=1e-12)
    model.ed(models.HINGE + 1, 1, 5.0)
    model.timestep(n_out, 20.0)
    res = spacar.simulate(model)
    assert res.stats["recursive"]
    tip = res.node(3).x
    np.testing.assert_allclose(tip[:, 0], np.cos(5.0 * res.t), atol=1e-6)
    np.testing.assert_allclose(tip[:, 1], np.sin(5.0 * res.t), atol=1e-6)
    np.testing.assert_allclose(res.deformation(models.HINGE + 1, 1), 5.0 * res.t, rtol=1e-8)
    np.testing.assert_allclose(res.deformation(models.HINGE + 2, 1), 0.0, atol=1e-8)


def test_blocks_continue_on_the_recursive_path():
    """Two blocks of 0.2 s on the recursive path end where one block of 0.4 s on the general path
    does; the concatenated results say that every block took the recursive path."""
    def chain():
        return models.planar_chain(3, angle=0.4, eps=1e-10, epskin=1e-12)
    model = chain()
    model.timestep(2, 0.2)
    first = spacar.simulate(model)
    model.timestep(2, 0.2)
    second = spacar.simulate(model)
    both = spacar.Results.concatenate([first, second])
    assert both.stats["recursive"] is True
    one = chain()
    one.timestep(4, 0.4)
    general = spacar.simulate(one, recursive=False)
    np.testing.assert_allclose(second.x[-1], general.x[-1], rtol=0, atol=1e-7)
    np.testing.assert_allclose(second.e[-1], general.e[-1], rtol=0, atol=1e-7)


def test_a_massless_mesh_names_a_few_degrees_of_freedom_and_counts_the_rest():
    from spacar.compare import models

    m = models.cantilever(12, rho_a=0.0)
    with pytest.raises(spacar.SingularMassError, match=r"deformation 3\] and 16 more move no mass") as info:
        spacar.simulate(m)
    assert len(info.value.args[0]) < 700


def test_a_tree_taken_before_time_loads_leaves_their_state_to_the_equations_of_motion():
    """recursive_state keeps its tree, which knows the constant loads only: with a time-dependent
    load set afterwards, evaluate_state solves the equations of motion (the load's accelerations
    included), as a simulation that never took the tree."""
    model = TREES["chain"]()
    with_tree, without = assembled(model.copy()), assembled(model.copy())
    nd, nx = with_tree.system.n_dof, with_tree.system.nx
    q, qd = np.array(with_tree.system.q0) + 0.1, np.full(nd, 0.3)
    assert with_tree.recursive_state(q, qd) is not None
    push = np.zeros(nx)
    push[nx - 3] = 5.0  # the last node's x (coordinates x, y, then its BETA node)
    for sim in (with_tree, without):
        sim.set_time_loads([], [], lambda t: push)
        sim.evaluate_state(0.0, np.concatenate([q, qd]))
    np.testing.assert_allclose(with_tree.data.xdd, without.data.xdd, rtol=0, atol=1e-10)
    np.testing.assert_allclose(with_tree.data.sigma, without.data.sigma, rtol=0, atol=1e-9)
    unloaded = assembled(model.copy())
    unloaded.evaluate_state(0.0, np.concatenate([q, qd]))
    assert np.abs(unloaded.data.xdd - without.data.xdd).max() > 1.0  # the load counts
