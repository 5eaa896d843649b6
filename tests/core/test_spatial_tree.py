"""The recursive path of spatial rigid trees (cpp/include/spacar/recursive/spatial_tree.hpp).

Its accelerations, positions and velocities are checked against the constraint formulation
(Newton and the sparse solve of the general path, which share nothing with it but the element mass
matrices) at states reached by continuation, and against Pinocchio's ABA on the same trees; runs on
both paths give the same output; spatial models that are not trees of DOF hinges take the general
path.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import spacar
from spacar.compare import models
from support.simulation import assembled, assert_start_rows_agree

G = 9.81


def _box(mass, a, b, c, rng):
    """A full inertia tensor: a box turned by a random rotation."""
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return Q @ (mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])) @ Q.T


def branched_tree(loads=True, seed=5):
    """A trunk hinged to a rotated ground, two branches hinged at its tip about different axes (one
    hinge points from the child to the parent, one body is two beams rigidly joined at a shared
    LAMBDA node), a grandchild on one branch at an offset point; EMASS with rotary inertia, point
    masses, full inertia tensors on LAMBDA nodes, a hinge spring-damper, gravity off the axes;
    ``loads``: TORQUEL on two bodies and FORCE on two points."""
    rng = np.random.default_rng(seed)
    m = spacar.Model()
    for node, p in {1: (0.1, -0.2, 0.3), 2: (0.5, 0.1, 0.8), 3: (0.9, 0.6, 0.7), 4: (0.3, 0.5, 1.2),
                    5: (0.1, 0.9, 1.3), 6: (1.2, 0.4, 1.1), 7: (1.0, 0.3, 0.2)}.items():
        m.xyz(node, *p)
    m.beam(1, 1, 11, 2, 12, 0.0, 0.0, 1.0)
    m.beam(2, 2, 21, 3, 22, 0.0, 1.0, 0.0)
    m.beam(3, 2, 31, 4, 32, 1.0, 0.0, 0.0)
    m.beam(4, 4, 32, 5, 42, 0.0, 0.0, 1.0)     # rigidly joined to beam 3 (LAMBDA node 32)
    m.beam(5, 3, 51, 6, 52, 1.0, 1.0, 0.0)     # the grandchild, hinged at node 3 of beam 2
    m.beam(6, 6, 52, 7, 62, 0.0, 1.0, 1.0)     # its second beam: node 7 is an offset point
    m.hinge(101, 100, 11, 0.3, -0.5, 0.8)
    m.hinge(102, 12, 21, 1.0, 0.2, -0.1)
    m.hinge(103, 31, 12, -0.2, 1.0, 0.4)       # from the child to the parent
    m.hinge(104, 22, 51, 0.1, 0.3, 1.0)
    for h in (101, 102, 103, 104):
        m.dyne(h, 1)
    m.fix(1)
    m.fix(100)
    m.lambda_(100, math.cos(0.2), *(math.sin(0.2) * np.array([0.6, 0.0, 0.8])))
    for e in range(1, 7):
        m.emass(e, 0.5 + rng.random(), 1e-3, 2e-3, 3e-3)
    m.mass(3, 0.2)
    m.mass(5, 0.1)
    m.mass(7, 0.3)
    for node, mass in ((21, 0.4), (32, 0.3), (52, 0.6)):
        J = _box(mass, *(0.1 + 0.2 * rng.random(3)), rng)
        m.mass(node, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
    m.estiff(103, 2.0)
    m.edampp(103, 0.1)
    if loads:
        m.torquel(21, 0.2, -0.1, 0.3)
        m.torquel(52, -0.1, 0.05, 0.2)
        m.force(5, 0.5, -0.2, 0.1)
        m.force(7, 0.0, 0.3, -0.4)
    m.gravity(1.0, -2.0, -G)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-13)
    m.timestep(3, 0.3)
    return m


def random_tree(n, seed, loads=True):
    """n bodies hung at random from the ground or an earlier body, at its end point or at an
    offset point of a second beam rigidly joined to it; hinges about random axes pointing either
    way, some with springs and dampers; random masses, inertia tensors and gravity; ``loads``:
    random TORQUEL and FORCE."""
    rng = np.random.default_rng(seed)
    m = spacar.Model()
    m.xyz(1, *rng.normal(size=3) * 0.1)
    points = {0: [1]}  # body → its points where children may hang (the ground: node 1)
    position = {1: np.array(m.nodes[1].x)}
    for i in range(1, n + 1):
        parent = int(rng.integers(0, i))
        pin = int(rng.choice(points[parent]))
        end, offset = 100 + i, 300 + i
        position[end] = position[pin] + rng.normal(size=3) * 0.4
        position[offset] = position[end] + rng.normal(size=3) * 0.2
        m.xyz(end, *position[end])
        m.xyz(offset, *position[offset])
        m.beam(i, pin, 1000 + i, end, 2000 + i, *rng.normal(size=3))
        m.beam(500 + i, end, 2000 + i, offset, 3000 + i, *rng.normal(size=3))  # rigidly joined
        parent_lambda = 10 if parent == 0 else 2000 + parent
        ends = (parent_lambda, 1000 + i) if rng.random() < 0.5 else (1000 + i, parent_lambda)
        m.hinge(700 + i, *ends, *rng.normal(size=3))
        m.dyne(700 + i, 1)
        m.emass(i, 0.5 + rng.random(), *(1e-3 * rng.random(3)))
        m.mass(offset, 0.1 + 0.2 * rng.random())
        J = _box(0.2 + 0.3 * rng.random(), *(0.1 + 0.2 * rng.random(3)), rng)
        m.mass(2000 + i, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
        torque, force = 0.2 * rng.normal(size=3), 0.3 * rng.normal(size=3)
        if loads:
            m.torquel(3000 + i, *torque)
            m.force(offset, *force)
        if rng.random() < 0.5:
            m.estiff(700 + i, rng.random())
            m.edampp(700 + i, 0.1 * rng.random())
        points[i] = [end, offset]
    m.fix(1)
    m.fix(10)
    m.gravity(*rng.normal(size=3) * 5.0)
    m.epskin(1e-13)
    return m


TREES = {
    "random tree 7": lambda: random_tree(7, seed=1),
    "random tree 9": lambda: random_tree(9, seed=2),
    "chain 6": lambda: models.spatial_chain(6, seed=6, epskin=1e-13),
    "chain springs": lambda: models.spatial_chain(4, seed=7, stiffness=2.5, epskin=1e-13),
    "chain straight ground": lambda: models.spatial_chain(3, seed=3, ground_rotation=False, epskin=1e-13),
    "branched": branched_tree,
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
    general path's continuation (move_to), so every hinge has turned."""
    sim = assembled(TREES[name]())
    q0 = np.array(sim.system.q0)
    assert sim.recursive_state(q0, np.zeros(q0.size)) is not None  # the tree, at the assembly
    rng = np.random.default_rng(11)
    for _ in range(5):
        q = q0 + rng.uniform(-1.0, 1.0, q0.size)
        qd = rng.uniform(-2.0, 2.0, q0.size)
        sim.move_to(0.0, q, qd)
        got = sim.recursive_state(q, qd)
        d = sim.data
        for key, expected, tol in (("qdd", d.qdd, 1e-11), ("x", d.x, 1e-11), ("xd", d.xd, 1e-11),
                                   ("xdd", d.xdd, 1e-10)):
            expected = np.array(expected)
            np.testing.assert_allclose(got[key], expected, rtol=0, atol=tol * max(1.0, np.abs(expected).max()),
                                       err_msg=key)


def test_an_output_time_takes_the_trees_positions_without_newton_iterations():
    """At an output time of the recursive path the tree's positions already satisfy the
    constraints: Newton checks them and does not iterate (no polish, no factorization), and they
    equal the general path's solution at the same state."""
    sim = assembled(models.spatial_chain(6, seed=6, epskin=1e-13))
    q0 = np.array(sim.system.q0)
    rng = np.random.default_rng(4)
    q, qd = q0 + rng.uniform(-1.0, 1.0, q0.size), rng.uniform(-2.0, 2.0, q0.size)
    sim.move_to(0.0, q, qd)
    general = np.array(sim.data.x)
    assert sim.data.newton_iterations > 0
    assert sim.recursive_state(q, qd) is not None
    sim.evaluate_state(0.0, np.concatenate([q, qd]))
    assert sim.data.newton_iterations == 0
    np.testing.assert_allclose(sim.data.x, general, rtol=0, atol=1e-12 * np.abs(general).max())


PINOCCHIO_TREES = {
    "chain 8": lambda: models.spatial_chain(8, seed=8, epskin=1e-13),
    "chain springs": lambda: models.spatial_chain(5, seed=2, stiffness=1.5, epskin=1e-13),
    "branched": lambda: branched_tree(loads=False),
    "random tree 8": lambda: random_tree(8, seed=3, loads=False),
}


@pytest.mark.parametrize("name", list(PINOCCHIO_TREES))
def test_recursive_accelerations_equal_pinocchio_aba(name):
    """The same tree built in Pinocchio (spacar.compare.pinocchio): its joint coordinates are the
    hinge angles (the sign of a hinge pointing to the parent turned), its forward kinematics puts
    the bodies where the recursive path does, and its ABA gives the same accelerations."""
    sp = pytest.importorskip("spacar.compare.pinocchio")
    model = PINOCCHIO_TREES[name]()
    pm = sp.build(model.copy())
    sim = assembled(model)
    q0 = np.array(sim.system.q0)
    n = q0.size
    dofs = list(sim.system.e_dyn)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = q0 + rng.uniform(-1.5, 1.5, n)
        qd = rng.uniform(-2.0, 2.0, n)
        got = sim.recursive_state(q, qd)
        # Pinocchio's joint coordinates: the hinge angles, by the converter's map of deformations.
        e, ed, edd = (np.zeros(sim.system.ne) for _ in range(3))
        e[dofs], ed[dofs], edd[dofs] = q, qd, got["qdd"]
        qp, vp = pm.configuration(got["x"], got["xd"], e, ed)
        assert pm.position_error(qp, got["x"]) < 1e-12
        a = pm.accelerations(got["x"], got["xd"], got["xdd"], e, ed, edd)
        aba = pm.aba(qp, vp)
        np.testing.assert_allclose(a, aba, rtol=0, atol=1e-11 * max(1.0, np.abs(aba).max()))


@pytest.mark.parametrize("name", ["chain springs", "branched"])
def test_runs_on_both_paths_agree(name):
    """Output times and everything reported there (positions and velocities solved by the
    general path from the tree's, accelerations and stresses from the tree's q̈) agree with a
    run on the general path."""
    model = TREES[name]()
    model.forcemode(1)
    model.timestep(3, 0.3)
    fast = spacar.simulate(model.copy())
    general = spacar.simulate(model.copy(), recursive=False)
    assert fast.stats["recursive"] and not general.stats["recursive"]
    assert fast.stats["newton_iterations"] < general.stats["newton_iterations"]
    np.testing.assert_array_equal(fast.t, general.t)
    for field in ("x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        a, b = getattr(fast, field), getattr(general, field)
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-7 * max(1.0, np.abs(b).max()), err_msg=field)


def spherical_joint():
    """A chain whose second link hangs from a shared node without a hinge (DYNX on its Euler
    parameters)."""
    return models.spatial_chain(2, seed=4, joints="spherical")


def rsur():
    from support.spatial_models import rssr_model

    return rssr_model(coupler="beam", dynamic=True)


def held_hinge():
    """A chain whose second hinge is held (e1 fixed): the two links are one body."""
    m = models.spatial_chain(1, seed=1)
    m.xyz(3, 2.0, 0.5, 0.0)
    m.beam(2, 2, 21, 3, 22, 0.0, 0.0, 1.0)
    m.hinge(9, models.END + 1, 21, 0.0, 1.0, 0.0)
    m.emass(2, 1.0)
    return m


def flexible_beam():
    from support.spatial_models import cantilever

    return cantilever(2)


def lambda_force():
    m = models.spatial_chain(2, seed=1)
    m.force(models.START + 1, 0.0, 0.1, 0.0, 0.0)
    return m


NOT_TREES = {
    "spherical joint (DYNX)": spherical_joint,
    "closed loop (RSUR)": rsur,
    "hinge held fixed": held_hinge,
    "flexible BEAM": flexible_beam,
    "FORCE on a LAMBDA node": lambda_force,
}


@pytest.mark.parametrize("name", list(NOT_TREES))
def test_other_spatial_models_take_the_general_path(name):
    model = NOT_TREES[name]()
    sim = assembled(model.copy())
    q0 = np.array(sim.system.q0)
    assert sim.recursive_state(q0, np.zeros(q0.size)) is None
    model.timestep(1, 1e-3)
    assert not spacar.simulate(model).stats["recursive"]


def test_a_body_without_mass_is_named_by_the_general_path():
    """Two links on parallel hinges, only the first with mass."""
    model = spacar.Model()
    model.xyz(1, 0.0, 0.0, 0.0)
    model.xyz(2, 1.0, 0.0, 0.0)
    model.xyz(3, 2.0, 0.0, 0.0)
    model.beam(1, 1, 11, 2, 12, 0.0, 1.0, 0.0)
    model.beam(2, 2, 21, 3, 22, 0.0, 1.0, 0.0)
    model.hinge(3, 10, 11, 0.0, 0.0, 1.0)
    model.hinge(4, 12, 21, 0.0, 0.0, 1.0)
    model.dyne(3, 1)
    model.dyne(4, 1)
    model.fix(1)
    model.fix(10)
    model.emass(1, 1.0)
    sim = assembled(model.copy())
    assert sim.recursive_state(np.zeros(2), np.zeros(2)) is None
    with pytest.raises(spacar.SingularMassError):
        spacar.simulate(model)


REASONS = {
    "spherical joint (DYNX)": "DYNX",
    "closed loop (RSUR)": "HINGE",
    "hinge held fixed": "not a revolute joint",
    "flexible BEAM": "(BEAM) is not rigid",
    "FORCE on a LAMBDA node": "FORCE on LAMBDA node 100001",
}


@pytest.mark.parametrize("name", list(REASONS))
def test_the_refusal_says_why(name):
    sim = assembled(NOT_TREES[name]())
    assert REASONS[name] in sim.recursive_refusal()
    assert assembled(branched_tree()).recursive_refusal() == ""


@pytest.mark.parametrize("n_out", [2, 10])
def test_output_times_of_a_fast_spin_stay_on_the_branch(n_out):
    """A straight 2-link chain on parallel hinges (axis (1, 1, 1)) spinning at 5 rad/s without
    gravity turns rigidly. Its steps grow long, so the output times are solved by Newton from the
    tree's positions there: the tip stays on its circle and the second hinge stays straight."""
    axis = np.ones(3) / np.sqrt(3.0)
    m = spacar.Model()
    m.xyz(1, 0.0, 0.0, 0.0)
    m.xyz(2, 0.5, -0.5, 0.0)
    m.xyz(3, 1.0, -1.0, 0.0)
    m.beam(1, 1, 11, 2, 12, *axis)
    m.beam(2, 2, 21, 3, 22, *axis)
    m.hinge(3, 10, 11, *axis)
    m.hinge(4, 12, 21, *axis)
    m.dyne(3, 1)
    m.dyne(4, 1)
    m.fix(1)
    m.fix(10)
    m.emass(1, 1.0)
    m.emass(2, 1.0)
    m.ed(3, 1, 5.0)
    m.epsint(1e-8)
    m.epsind(1e-8)
    m.epskin(1e-12)
    m.timestep(n_out, 20.0)
    res = spacar.simulate(m)
    assert res.stats["recursive"]
    tip = res.node(3).x
    r0 = np.array([1.0, -1.0, 0.0])
    for k, t in enumerate(res.t):  # Rodrigues: r0 ⟂ axis
        expected = np.cos(5.0 * t) * r0 + np.sin(5.0 * t) * np.cross(axis, r0)
        np.testing.assert_allclose(tip[k], expected, atol=1e-6)
    np.testing.assert_allclose(res.deformation(3, 1), 5.0 * res.t, rtol=1e-8)
    np.testing.assert_allclose(res.deformation(4, 1), 0.0, atol=1e-8)
