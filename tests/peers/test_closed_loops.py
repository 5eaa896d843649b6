"""Closed loops against Pinocchio's constrained dynamics (issue 37): the accelerations of
spacar's recursive path (the tree with its loops closed, closed_loop.hpp) and of its general path
(the constraint formulation) equal ``pinocchio.constraintDynamics`` — Pinocchio's tree with the loop closed by a rigid point
constraint, an independent formulation — along a run, at each output time's state:

* the free four-bar of ``spacar.compare.models.four_bar`` (rods, a point mass, gravity; the
  loop closed at the coupler–rocker pin by a 3-D point constraint, whose out-of-plane row is
  redundant: Pinocchio's proximal solver takes the minimum-norm multipliers);
* the spatial RSUR linkage of tests/support/spatial_models.py (a crank, a rocker with a universal
  joint to the coupler, the loop closed at the crank's spherical joint; rods, a point mass and a
  rigid body on the coupler, gravity).

spacar's states come from DOP853 runs with EPSKIN 1e-14, so that each output time's positions
close the loop to round-off; both programs then see the same state."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar.compare import models
from support.constraints import constrained
from support.spatial_models import RSSR, rssr_model, unit

pin = pytest.importorskip("pinocchio")

G = 9.81


def rod(mass_per_length, p0, p1, origin):
    """A uniform thin rod from p0 to p1 as a Pinocchio inertia about `origin` (the joint frame's
    origin, its axes the world's at the reference state)."""
    d = p1 - p0
    length = np.linalg.norm(d)
    u = d / length
    m = mass_per_length * length
    return pin.Inertia(m, (p0 + p1) / 2 - origin, m * length**2 / 12 * (np.eye(3) - np.outer(u, u)))


def tight(model):
    model.epskin(1e-14)
    model.epsint(1e-8)
    model.epsind(1e-8)
    return model


@pytest.mark.parametrize("recursive", [True, False])
def test_four_bar_matches_constraint_dynamics(recursive):
    A, B, C, D = (np.array(p, float) for p in ([0, 0, 0], [0, 1, 0], [2, 1.5, 0], [2.5, 0, 0]))
    pm = pin.Model()
    pm.gravity.linear = np.array([0.0, -G, 0.0])
    crank = pm.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), A), "crank")
    pm.appendBodyToJoint(crank, rod(1.0, A, B, A), pin.SE3.Identity())
    coupler = pm.addJoint(crank, pin.JointModelRZ(), pin.SE3(np.eye(3), B - A), "coupler")
    pm.appendBodyToJoint(coupler, rod(1.5, B, C, B), pin.SE3.Identity())
    pm.appendBodyToJoint(coupler, pin.Inertia(0.3, C - B, np.zeros((3, 3))), pin.SE3.Identity())
    rocker = pm.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), D), "rocker")
    pm.appendBodyToJoint(rocker, rod(1.2, D, C, D), pin.SE3.Identity())
    accelerations = constrained(pm, coupler, C - B, rocker, C - D)

    res = spacar.simulate(tight(models.four_bar(t_end=1.0, n_out=10)), method="dop853", recursive=recursive)
    assert res.stats["path"] == ("tree" if recursive else "general")
    # Pinocchio's joints: the crank's rotation, the coupler's relative to the crank, the rocker's,
    # from the reference state (spacar's BETA nodes 11, 21, 31 hold the links' absolute angles).
    angle = {b: res.coordinate(b, 1, "x") for b in (11, 21, 31)}
    rate = {b: res.coordinate(b, 1, "xd") for b in (11, 21, 31)}
    acc = {b: res.coordinate(b, 1, "xdd") for b in (11, 21, 31)}
    for k in range(len(res.t)):
        q = np.array([angle[11][k] - angle[11][0], angle[21][k] - angle[21][0] - (angle[11][k] - angle[11][0]),
                      angle[31][k] - angle[31][0]])
        v = np.array([rate[11][k], rate[21][k] - rate[11][k], rate[31][k]])
        ours = np.array([acc[11][k], acc[21][k] - acc[11][k], acc[31][k]])
        theirs = accelerations(q, v)
        assert np.abs(ours - theirs).max() <= 1e-10 * max(1.0, np.abs(theirs).max()), (k, ours, theirs)


@pytest.mark.parametrize("recursive", [True, False])
def test_spatial_rsur_matches_constraint_dynamics(recursive):
    g = RSSR
    B, C = g.B(0.0), g.C(g.phi(0.0))
    A, D = np.asarray(g.A, float), np.asarray(g.D, float)
    uA, uD = unit(np.asarray(g.uA, float)), unit(np.asarray(g.uD, float))
    u2 = unit(np.cross(uD, C - B))  # the universal joint's second axis (HINGE 8)
    pm = pin.Model()
    pm.gravity.linear = np.array([0.0, 0.0, -G])
    crank = pm.addJoint(0, pin.JointModelRevoluteUnaligned(uA), pin.SE3(np.eye(3), A), "crank")
    pm.appendBodyToJoint(crank, rod(1.0, A, B, A), pin.SE3.Identity())
    rocker = pm.addJoint(0, pin.JointModelRevoluteUnaligned(uD), pin.SE3(np.eye(3), D), "rocker")
    pm.appendBodyToJoint(rocker, rod(0.8, D, C, D), pin.SE3.Identity())
    pm.appendBodyToJoint(rocker, pin.Inertia(0.2, C - D, np.zeros((3, 3))), pin.SE3.Identity())
    cross = pm.addJoint(rocker, pin.JointModelRevoluteUnaligned(uD), pin.SE3(np.eye(3), C - D), "cross")
    coupler = pm.addJoint(cross, pin.JointModelRevoluteUnaligned(u2), pin.SE3.Identity(), "coupler")
    pm.appendBodyToJoint(coupler, rod(0.5, C, B, C), pin.SE3.Identity())
    body = np.diag([0.01, 0.02, 0.03])  # MASS on the coupler's LAMBDA node 16
    pm.appendBodyToJoint(coupler, pin.Inertia(0.0, np.zeros(3), body), pin.SE3.Identity())
    accelerations = constrained(pm, crank, B - A, coupler, B - C)

    res = spacar.simulate(tight(rssr_model(coupler="beam", dynamic=True, n_out=10, period=1.0)), method="dop853",
                          recursive=recursive)
    assert res.stats["path"] == ("tree" if recursive else "general")
    hinges = (5, 6, 7, 8)  # crank (DYNE), rocker and the universal joint's two (released): Pinocchio's joints
    e, ed, edd = (np.column_stack([res.deformation(h, 1, what) for h in hinges]) for what in ("e", "ed", "edd"))
    for k in range(len(res.t)):
        theirs = accelerations(e[k], ed[k])
        assert np.abs(edd[k] - theirs).max() <= 1e-10 * max(1.0, np.abs(theirs).max()), (k, edd[k], theirs)
