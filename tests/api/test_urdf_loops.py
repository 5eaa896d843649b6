"""Closed loops beside a URDF (from_urdf(..., loops=[...], dependent=[...]), issue 37): the
spatial RSUR linkage written as a URDF tree (tests/data/rsur_loop.urdf: a crank, a rocker with a
universal joint to the coupler) and its loop closed by a ball joint between the coupler's end and
the crank. Its run's accelerations at every output time equal ``pinocchio.constraintDynamics`` of
Pinocchio's model of the same file with the same point constraint, and the run equals the
hand-built model of tests/peers/test_closed_loops.py."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from support.constraints import constrained
from support.paths import DATA

URDF = DATA / "rsur_loop.urdf"
BALL = {"parent": "crank", "child": "coupler", "xyz": (0.2, 0.0, 0.0), "type": "spherical", "name": "ball"}
DEPENDENT = ["rocker", "cross", "coupler"]


def rsur(rate=1.5):
    model = spacar.from_urdf(URDF, loops=[BALL], dependent=DEPENDENT)
    model.ed(1, 1, rate)
    model.timestep(10, 1.0)
    model.epskin(1e-14)
    model.epsint(1e-8)
    model.epsind(1e-8)
    return model


pytestmark = pytest.mark.filterwarnings("ignore:.*joint limits")


@pytest.mark.parametrize("recursive", [True, False])
def test_loop_closed_by_a_ball_joint_matches_constraint_dynamics(recursive):
    """On the recursive path (the tree's inverse dynamics with the loop closed by Newton's method
    in the three dependent joints, closed_loop.hpp) and on the general path."""
    pin = pytest.importorskip("pinocchio")
    model = rsur()
    assert model.urdf_joints == ["crank", "rocker", "cross", "coupler"]
    res = spacar.simulate(model, method="dop853", recursive=recursive)
    assert res.dof_labels == ["e(1,1) HINGE"] and res.stats["path"] == ("tree" if recursive else "general")

    pm = pin.buildModelFromUrdf(str(URDF))
    crank, coupler = pm.getJointId("crank"), pm.getJointId("coupler")
    B = np.array([0.2, 0.0, 0.0])  # the ball: in the crank's frame, and from the coupler's origin C
    C = np.asarray(pm.jointPlacements[pm.getJointId("cross")].translation) + \
        np.asarray(pm.jointPlacements[pm.getJointId("rocker")].translation)
    accelerations = constrained(pm, crank, B, coupler, B - C)

    joints = range(1, 5)  # elements 1..4: the URDF's joints in Pinocchio's order
    e, ed, edd = (np.column_stack([res.deformation(k, 1, what) for k in joints]) for what in ("e", "ed", "edd"))
    assert np.ptp(e[:, 0]) > 1.0  # the crank turned
    for k in range(len(res.t)):
        theirs = accelerations(e[k], ed[k])
        assert np.abs(edd[k] - theirs).max() <= 1e-8 * max(1.0, np.abs(theirs).max()), (k, edd[k], theirs)


def test_the_same_run_as_the_hand_built_linkage():
    """The URDF's linkage and the element model of tests/support/spatial_models.py (the RSUR with
    the same rods, masses and body) run the same motion."""
    from support.spatial_models import rssr_model

    hand = rssr_model(coupler="beam", dynamic=True, n_out=10, period=1.0)
    for eps in (hand.epskin, ):
        eps(1e-14)
    hand.epsint(1e-8)
    hand.epsind(1e-8)
    ours = spacar.simulate(rsur(), method="dop853")
    theirs = spacar.simulate(hand, method="dop853")
    e_ours = np.column_stack([ours.deformation(k, 1, "e") for k in range(1, 5)])
    e_theirs = np.column_stack([theirs.deformation(k, 1, "e") for k in (5, 6, 7, 8)])
    assert np.abs(e_ours - e_theirs).max() < 1e-7


def test_revolute_loop_joint_adds_a_hinge_and_over_constraint_is_named():
    """A revolute loop joint: a HINGE between the two bodies, its rotation released. At the RSUR's
    ball it over-constrains the loop (five constraints, three dependent joints): said when the
    model is built, and the assembly names the loop hinge's misalignments as the redundant ones."""
    with pytest.warns(UserWarning, match="add 5 constraints and 3 joints are dependent"):
        model = spacar.from_urdf(URDF, loops=[dict(BALL, type="revolute", axis=(0.0, 0.0, 1.0))],
                                 dependent=DEPENDENT)
    types = [model.core.element_type_name(k) for k in sorted(model.elements)]
    assert types.count("HINGE") == 5  # the four joints and the loop's
    loop = max(k for k in model.elements if model.core.element_type_name(k) == "HINGE")
    model.timestep(1, 0.1)
    with pytest.raises(spacar.KinematicsError, match=rf"RLSE {loop} 2.*\n.*RLSE {loop} 3"):
        spacar.simulate(model)


@pytest.mark.parametrize("kw, message", [
    (dict(loops=[dict(BALL, parent="nope")]), "parent 'nope' is not a link"),
    (dict(loops=[dict(BALL, child="crank")]), "the same link"),
    (dict(loops=[dict(BALL, type="weld")]), "type must be one of"),
    (dict(loops=[dict(BALL, type="revolute")]), "needs a nonzero axis"),
    (dict(loops=[dict(BALL, axis=(1, 0, 0))]), "has no axis"),
    (dict(loops=[dict(BALL, xyz=(0, 0))]), "three finite numbers"),
    (dict(loops=[dict(BALL, color="red")]), "unknown keys"),
    (dict(loops=BALL), "list of loop joints"),
    (dict(loops=[BALL], dependent=["elbow"]), "not a moving joint"),
    (dict(dependent=["rocker"]), "need loop joints"),
    (dict(loops=[BALL], dependent=["crank", "rocker", "cross", "coupler"]), "cannot determine them"),
])
def test_bad_loops_are_refused_naming_the_file(kw, message):
    with pytest.raises(spacar.InputError, match=message) as info:
        spacar.from_urdf(URDF, **kw)
    assert "rsur_loop.urdf" in str(info.value)


def test_recursive_accelerations_equal_constraint_dynamics_at_fixed_states():
    """The recursive path's q̈ (closed_loop.hpp) at states the general path reaches by continuation
    equals pinocchio.constraintDynamics at the joints' values there, to round-off."""
    pin = pytest.importorskip("pinocchio")
    from support.simulation import assembled

    pm = pin.buildModelFromUrdf(str(URDF))
    crank, coupler = pm.getJointId("crank"), pm.getJointId("coupler")
    B = np.array([0.2, 0.0, 0.0])
    C = np.asarray(pm.jointPlacements[pm.getJointId("cross")].translation) + \
        np.asarray(pm.jointPlacements[pm.getJointId("rocker")].translation)
    accelerations = constrained(pm, crank, B, coupler, B - C)
    sim = assembled(rsur())
    labels = [tuple(label) for label in sim.system.def_label]
    joints = [labels.index((k, 1)) for k in range(1, 5)]
    q0 = np.array(sim.system.q0)
    rng = np.random.default_rng(11)
    for _ in range(5):
        q, qd = q0 + rng.uniform(-1.0, 1.0, 1), rng.uniform(-2.0, 2.0, 1)
        sim.move_to(0.0, q, qd)
        e, ed = np.array(sim.data.e)[joints], np.array(sim.data.ed)[joints]
        theirs = accelerations(e, ed)[0]
        ours = sim.recursive_state(q, qd)["qdd"][0]
        assert abs(ours - theirs) <= 1e-12 * max(1.0, abs(theirs)), (ours, theirs)
