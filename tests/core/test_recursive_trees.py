"""The recursive path of rigid trees: one articulated-body algorithm over the planar and the
spatial algebra (cpp/include/spacar/recursive/articulated.hpp, planar_tree.hpp, spatial_tree.hpp;
formulation.md §7).

Its accelerations, positions and velocities are checked against the constraint formulation
(Newton and the sparse solve of the general path, which share nothing with it but the element mass
matrices) at states reached by continuation, and against Pinocchio's ABA on the same trees; runs on
both paths give the same motion and output; models that are not trees of rigid bodies on joints
take the general path and say why. The pendulum periods of test_planar_dynamics.py (elliptic
integrals) and the chain trajectories of test_compare.py (exudyn, Pinocchio) run on this path too.
"""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar.compare import models
from support import trees
from support.paths import DATA
from support.simulation import assembled, assert_start_rows_agree

TREES = {
    "planar chain": lambda: models.planar_chain(6, rho_a=1.5, tip_mass=0.3, joint_inertia=0.02, angle=0.3),
    "planar chain springs": lambda: models.planar_chain(4, stiffness=3.0, damping=0.2, ground_angle=0.3, angle=-0.2),
    "planar chain absolute": lambda: models.planar_chain(5, dof="absolute", angle=0.3),
    "planar chain absolute springs": lambda: models.planar_chain(5, dof="absolute", stiffness=3.0, damping=0.2),
    "planar branched": trees.planar_branched_tree,
    "planar branched spring": lambda: trees.planar_branched_tree(spring=True),
    "planar PLBEAMNL, DYNX": trees.plbeamnl_chain,
    "spatial random tree 7": lambda: trees.random_tree(7, seed=1),
    "spatial random tree 9": lambda: trees.random_tree(9, seed=2),
    "spatial chain 6": lambda: models.spatial_chain(6, seed=6, epskin=1e-13),
    "spatial chain springs": lambda: models.spatial_chain(4, seed=7, stiffness=2.5, epskin=1e-13),
    "spatial chain straight ground": lambda: models.spatial_chain(3, seed=3, ground_rotation=False, epskin=1e-13),
    "spatial branched": trees.spatial_branched_tree,
    "spatial URDF wrist": lambda: trees.urdf(DATA / "wrist.urdf"),
    "spatial URDF prismatic": lambda: trees.urdf(DATA / "prismatic.urdf"),
    "spatial loop RSUR": trees.rsur,
    "spatial loop URDF RSUR": trees.urdf_rsur,
    "spatial loop 7R": trees.seven_bar,
    "spatial loop 7R, its DOF mid-loop": lambda: trees.seven_bar(dof=4),
    "planar loop four-bar": lambda: models.four_bar(eps=1e-10, epskin=1e-14),
    "planar loop hinged four-bar": trees.hinged_four_bar,
    "planar loop four-bar driven between crank and coupler": trees.four_bar_driven_between_links,
}

# The states of the comparison with the constraint formulation: the random generator's seed and
# the tolerances of q̈, x, ẋ, ẍ (relative to the largest value, at least 1).
STATE_CHECKS = {
    "planar": (7, {"qdd": 1e-11, "x": 1e-9, "xd": 1e-9, "xdd": 1e-9}),
    "spatial": (11, {"qdd": 1e-11, "x": 1e-11, "xd": 1e-11, "xdd": 1e-10}),
}


def algebra(name):
    return name.split()[0]


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
    seed, tolerances = STATE_CHECKS[algebra(name)]
    rng = np.random.default_rng(seed)
    span = 0.3 if "loop" in name else 1.0  # loops lock beyond (the 7R)
    for _ in range(5):
        q = q0 + rng.uniform(-span, span, q0.size)
        qd = rng.uniform(-2.0, 2.0, q0.size)
        sim.move_to(0.0, q, qd)  # Newton along the path, the sparse solve of the constraint formulation
        got = sim.recursive_state(q, qd)
        d = sim.data
        for key, expected in (("qdd", d.qdd), ("x", d.x), ("xd", d.xd), ("xdd", d.xdd)):
            expected = np.array(expected)
            np.testing.assert_allclose(got[key], expected, rtol=0,
                                       atol=tolerances[key] * max(1.0, np.abs(expected).max()), err_msg=key)


def test_planar_recursive_accelerations_equal_pinocchio_aba():
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


PINOCCHIO_TREES = {
    "chain 8": lambda: models.spatial_chain(8, seed=8, epskin=1e-13),
    "chain springs": lambda: models.spatial_chain(5, seed=2, stiffness=1.5, epskin=1e-13),
    "branched": lambda: trees.spatial_branched_tree(loads=False),
    "random tree 8": lambda: trees.random_tree(8, seed=3, loads=False),
}


@pytest.mark.parametrize("name", list(PINOCCHIO_TREES))
def test_spatial_recursive_accelerations_equal_pinocchio_aba(name):
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


@pytest.mark.parametrize("name", ["planar chain springs", "planar chain absolute springs", "planar branched spring",
                                  "spatial chain springs", "spatial branched", "spatial URDF wrist",
                                  "spatial URDF prismatic", "spatial loop RSUR", "spatial loop URDF RSUR",
                                  "spatial loop 7R", "spatial loop 7R, its DOF mid-loop", "planar loop four-bar",
                                  "planar loop hinged four-bar",
                                  "planar loop four-bar driven between crank and coupler"])
def test_runs_on_both_paths_agree(name):
    """Output times and everything reported there (positions and velocities solved by the
    general path from the tree's, accelerations and stresses from the tree's q̈) agree with a
    run on the general path."""
    model = TREES[name]()
    model.forcemode(1)
    if algebra(name) == "planar":
        model.epsint(1e-10)
        model.epsind(1e-10)
    model.timestep(3, 0.3)
    fast = spacar.simulate(model.copy())
    general = spacar.simulate(model.copy(), recursive=False)
    assert fast.stats["recursive"] and not general.stats["recursive"]
    assert fast.stats["newton_iterations"] < general.stats["newton_iterations"]
    np.testing.assert_array_equal(fast.t, general.t)
    for field in ("x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        a, b = getattr(fast, field), getattr(general, field)
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-7 * max(1.0, np.abs(b).max()), err_msg=field)


# Models near a tree that are not one, and the part of the reason recursive_refusal() gives.
NOT_TREES = {
    "planar hinge held fixed": (trees.planar_held_hinge, "neither a joint (DYNE) nor released"),
    "planar DYNX on a position": (trees.position_dof, "is not a rotation"),
    "planar PLTRUSS": (trees.truss_brace, "(PLTRUSS) is not a PLBEAM or PLHINGE"),
    "planar flexible links": (lambda: models.cantilever(3), "(PLBEAM) is not rigid"),
    "planar input-driven slider-crank": (lambda: models.slider_crank(n_rod=2, t_end=0.01, n_out=1),
                                         "prescribed motions"),
    "spatial spherical joint (DYNX)": (trees.spherical_joint, "DYNX"),
    "spatial hinge held fixed": (trees.spatial_held_hinge, "not a revolute joint"),
    "spatial flexible BEAM": (trees.flexible_beam, "(BEAM) is not rigid"),
    "spatial FORCE on a LAMBDA node": (trees.lambda_force, "FORCE on LAMBDA node 100001"),
    "spatial loop cut at a hinge with a spring": (trees.rsur_sprung_cut, "closes a loop and has a law"),
}


@pytest.mark.parametrize("name", list(NOT_TREES))
def test_other_models_take_the_general_path(name):
    model = NOT_TREES[name][0]()
    sim = assembled(model.copy())
    q0 = np.array(sim.system.q0)
    if q0.size:
        assert sim.recursive_state(q0, np.zeros(q0.size)) is None
    model.timestep(1, 1e-3)
    assert not spacar.simulate(model).stats["recursive"]


@pytest.mark.parametrize("name", list(NOT_TREES))
def test_the_refusal_says_why(name):
    build, reason = NOT_TREES[name]
    assert reason in assembled(build()).recursive_refusal()


@pytest.mark.parametrize("name", ["planar branched", "spatial branched", "spatial URDF wrist"])
def test_a_tree_is_not_refused(name):
    assert assembled(TREES[name]()).recursive_refusal() == ""


@pytest.mark.parametrize("build, match", [(trees.planar_massless_chain, "move no mass"),
                                          (trees.spatial_massless_chain, None)], ids=["planar", "spatial"])
def test_a_body_without_mass_is_named_by_the_general_path(build, match):
    model = build()
    sim = assembled(model.copy())
    assert sim.recursive_state(np.zeros(2), np.zeros(2)) is None
    with pytest.raises(spacar.SingularMassError, match=match):
        spacar.simulate(model)


@pytest.mark.parametrize("bad", ["no", 2, 1, 0.0, None])
def test_recursive_must_be_a_boolean(bad):
    with pytest.raises(spacar.InputError, match="recursive must be True or False"):
        spacar.simulate(models.planar_chain(2), recursive=bad)


@pytest.mark.parametrize("n_out", [2, 10])
def test_output_times_of_a_fast_planar_spin_stay_on_the_branch(n_out):
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


@pytest.mark.parametrize("n_out", [2, 10])
def test_output_times_of_a_fast_spatial_spin_stay_on_the_branch(n_out):
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
    m = models.cantilever(12, rho_a=0.0)
    with pytest.raises(spacar.SingularMassError, match=r"deformation 3\] and 16 more move no mass") as info:
        spacar.simulate(m)
    assert len(info.value.args[0]) < 700


def test_a_tree_taken_before_time_loads_leaves_their_state_to_the_equations_of_motion():
    """recursive_state keeps its tree, which knows the constant loads only: with a time-dependent
    load set afterwards, evaluate_state solves the equations of motion (the load's accelerations
    included), as a simulation that never took the tree."""
    model = TREES["planar chain"]()
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


def test_a_far_state_does_not_switch_a_loop_to_its_other_assembly():
    """The loops are closed by continuation from the last closed state (closed_loop.hpp): after a
    state four radians of crank away, a state near the start is solved on the start's assembly
    branch, as the general path's continuation solves it (from the warm start alone, Newton's
    method converged on the other branch: q̈ −41.4 against 45.2)."""
    general = assembled(trees.rsur())
    q0 = np.array(general.system.q0)
    rate = np.zeros(1)
    general.move_to(0.0, q0 + 0.05, rate)
    sim = assembled(trees.rsur())
    sim.recursive_state(q0 + 4.0, rate)
    got = sim.recursive_state(q0 + 0.05, rate)
    np.testing.assert_allclose(got["qdd"], general.data.qdd, rtol=1e-10)
    np.testing.assert_allclose(got["x"], general.data.x, rtol=0, atol=1e-10)


def test_a_loose_tolerance_keeps_the_loop_on_its_branch():
    """At the default EPSINT of 1e-3 the integrator tries stages far apart (rejected steps): the
    loops stay on the branch of the general path's run."""
    model = trees.rsur()
    model.epsint(1e-3)
    model.epsind(1e-3)
    model.timestep(4, 0.4)
    fast = spacar.simulate(model.copy(), method="dop853")
    general = spacar.simulate(model.copy(), method="dop853", recursive=False)
    assert fast.stats["path"] == "tree" and fast.stats["rejected"] > 0
    np.testing.assert_allclose(fast.x, general.x, rtol=0, atol=0.05)  # the two branches: 1.1 apart


def test_a_loop_is_cut_at_a_hinge_without_a_law():
    """Of the 7R loop's passive hinges the one with a spring is a joint of the tree, another the cut."""
    model = trees.seven_bar()
    model.estiff(models.HINGE + 7, 50.0)  # the cut without it
    model.edampp(models.HINGE + 7, 2.0)
    assert assembled(model.copy()).recursive_refusal() == ""
    model.timestep(2, 0.2)
    fast = spacar.simulate(model.copy())
    general = spacar.simulate(model.copy(), recursive=False)
    assert fast.stats["path"] == "tree"
    np.testing.assert_allclose(fast.x, general.x, rtol=0, atol=1e-8)


def test_a_crank_many_turns_round():
    """A crank 409 rad round (65 turns) from the assembled state, in one call: the continuation's
    tolerances follow the coordinates' own round-off (3e-14 at 300 rad), as the general path's
    continuation solves it."""
    general = assembled(models.four_bar(eps=1e-10, epskin=1e-14))
    q, qd = np.array([409.0]), np.array([0.5])
    general.move_to(0.0, q, qd)
    got = assembled(models.four_bar(eps=1e-10, epskin=1e-14)).recursive_state(q, qd)
    assert got is not None
    np.testing.assert_allclose(got["qdd"], general.data.qdd, rtol=1e-9)


def test_a_state_next_to_a_fold_does_not_stick():
    """After states up to 1e-9 from a fold of the loop (the rocker-driven four-bar's crank and
    coupler in line), states away from it close again (from the recognized state when the steep
    tangent at the fold stops the continuation), equal to a fresh tree's."""
    fold = -0.400625
    path = np.linspace(0.0, fold + 1e-9, 300)[:, None]
    dyn = spacar.Dynamics(trees.rocker_driven_four_bar())
    dyn.inverse_dynamics(path, 0.0 * path, 0.0 * path)
    for q in (0.0, -0.2, -0.35):
        state = np.array([q])
        fresh = spacar.Dynamics(trees.rocker_driven_four_bar()).inverse_dynamics(state, np.zeros(1), np.zeros(1))
        np.testing.assert_allclose(dyn.inverse_dynamics(state, np.zeros(1), np.zeros(1)), fresh, rtol=1e-10)
