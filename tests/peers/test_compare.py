"""Cross-checks against Pinocchio and exudyn (issue #8), through spacar.compare:

* N-link planar and spatial pendulum chains: spacar's reduced mass matrix M̄ and accelerations
  equal Pinocchio's CRBA and ABA to 1e-10 at random states (relative joint angles as DOFs, so
  that spacar's q is Pinocchio's q; other DOF choices through the exact velocity map T);
* trajectories of chains, a double pendulum and a four-bar agree with exudyn (kinematic tree +
  DOPRI5, or redundant coordinates + generalized-α) within the integrators' tolerances, and with
  Pinocchio's ABA integrated by the same DOP853;
* the manual's flexible slider-crank against exudyn's ANCF cable model: agreement within the
  discretisation differences explained in docs/comparison.md, shrinking under mesh refinement;
* the converters refuse what they cannot express, with a message naming it.

Skipped when the peers are not installed (they are in the ``test`` extra).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import spacar
from spacar.compare import UnsupportedModelError, models

pin = pytest.importorskip("pinocchio")
exu = pytest.importorskip("exudyn")

from spacar.compare import exudyn as sp_exudyn  # noqa: E402
from spacar.compare import pinocchio as sp_pinocchio  # noqa: E402


def assert_matches_pinocchio(model, n_states=6, scale_q=1.0, seed=0, identity_map=True):
    states = sp_pinocchio.random_states(model, n_states, seed=seed, scale_q=scale_q, scale_qd=2.0)
    r = sp_pinocchio.side_by_side(model, states)
    # the same configuration: Pinocchio's forward kinematics reproduces spacar's positions
    assert r["position_error"].max() < 1e-12
    scale_m = max(1.0, np.abs(r["M_pinocchio"]).max())
    assert np.abs(r["Mbar"] - r["M_pinocchio"]).max() <= 1e-10 * scale_m
    scale_a = max(1.0, np.abs(r["a_pinocchio"]).max())
    assert np.abs(r["a_spacar"] - r["a_pinocchio"]).max() <= 1e-10 * scale_a
    if identity_map:
        for T in r["T"]:
            np.testing.assert_allclose(T, np.eye(T.shape[0]), atol=1e-12)
        # spacar's own DOFs are Pinocchio's coordinates
        np.testing.assert_allclose(r["Mbar"], r["M_crba"], atol=1e-10 * scale_m, rtol=0)
        np.testing.assert_allclose(r["qdd"], r["a_pinocchio"], atol=1e-10 * scale_a, rtol=0)
    return r


# --------------------------------------------------------------------------------------------
# Pinocchio: mass matrix and accelerations at random states
# --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("n", [1, 2, 5, 12])
def test_planar_chain_matches_crba_and_aba(n):
    model = models.planar_chain(n, rho_a=1.5, tip_mass=0.3, joint_inertia=0.02, angle=-0.4, epskin=1e-12)
    assert_matches_pinocchio(model)


def test_planar_chain_springs_dampers_ground_rotation():
    """Hinge ESTIFF/EDAMPP are joint springs and dampers (τ = −St θ − d θ̇); a rotated fixed
    ground BETA node rotates the first joint frame; gravity off the axes."""
    model = models.planar_chain(4, rho_a=1.0, tip_mass=0.5, stiffness=3.0, damping=0.2, ground_angle=0.3,
                                gravity=(1.0, -models.G), epskin=1e-12)
    assert_matches_pinocchio(model)


def test_planar_chain_absolute_angles():
    """DYNX on the BETA nodes (absolute link rotations): spacar's DOFs are not Pinocchio's q;
    M̄ = Tᵀ M T with T the (constant, bidiagonal) map of absolute to relative rates."""
    model = models.planar_chain(5, rho_a=1.0, tip_mass=0.2, dof="absolute", epskin=1e-12)
    r = assert_matches_pinocchio(model, identity_map=False)
    T = r["T"][0]
    np.testing.assert_allclose(T, np.eye(5) - np.eye(5, k=-1), atol=1e-12)


@pytest.mark.parametrize("n", [1, 5, 9])
def test_planar_chain_dynamics_derivatives_match_compute_aba_derivatives(n):
    """spacar.dynamics_derivatives on a planar tree (issue 37): q̈, ∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M⁻¹
    of a pendulum chain equal pinocchio.computeABADerivatives at random states and torques, to
    1e-10 of each matrix's largest entry (relative joint angles: spacar's DOFs are Pinocchio's q
    up to constant offsets)."""
    model = models.planar_chain(n, rho_a=1.5, tip_mass=0.3, joint_inertia=0.02, angle=-0.4, epskin=1e-12)
    pm = sp_pinocchio.build(model)
    rng = np.random.default_rng(n)
    states = sp_pinocchio.random_states(model, 4, seed=n, scale_q=1.0, scale_qd=2.0)
    q = np.array([s[1] for s in states])
    qd = np.array([s[2] for s in states])
    tau = rng.uniform(-2.0, 2.0, q.shape)
    qdd, dq, dqd, dtau = spacar.dynamics_derivatives(model, q, qd, tau)
    for k, (t, qk, qdk) in enumerate(states):
        r = pm.spacar_state(t, qk, qdk)
        np.testing.assert_allclose(r["T"], np.eye(n), atol=1e-12)
        ref = pin.computeABADerivatives(pm.model, pm.data, r["q_pin"], r["v_pin"], tau[k])
        expected = pin.aba(pm.model, pm.data, r["q_pin"], r["v_pin"], tau[k])
        assert np.abs(qdd[k] - expected).max() <= 1e-10 * max(1.0, np.abs(expected).max())
        minv = np.triu(ref[2]) + np.triu(ref[2], 1).T
        for ours, theirs in zip((dq[k], dqd[k], dtau[k]), (ref[0], ref[1], minv)):
            assert np.abs(ours - theirs).max() <= 1e-10 * max(1.0, np.abs(theirs).max())


@pytest.mark.parametrize("case", ["springs", "absolute"])
def test_planar_tree_derivatives_against_differences(case):
    """What Pinocchio's derivatives do not cover: hinge springs and dampers (their torques depend on
    q and q̇), a rotated ground, gravity off the axes, and absolute link rotations as DOFs (DYNX on
    BETA nodes). ∂q̈/∂q and ∂q̈/∂q̇ equal central differences of q̈ (itself Pinocchio's ABA, above
    and in test_planar_chain_*) to 1e-7."""
    if case == "springs":
        model = models.planar_chain(4, rho_a=1.0, tip_mass=0.5, stiffness=3.0, damping=0.2, ground_angle=0.3,
                                    gravity=(1.0, -models.G), epskin=1e-12)
    else:
        model = models.planar_chain(5, rho_a=1.0, tip_mass=0.2, dof="absolute", epskin=1e-12)
    (_, q, qd), = sp_pinocchio.random_states(model, 1, seed=3, scale_q=1.0, scale_qd=2.0)
    tau = np.linspace(-1.0, 1.0, q.size)
    qdd, dq, dqd, _ = spacar.dynamics_derivatives(model, q, qd, tau)
    h = 1e-6
    for j in range(q.size):
        e = np.zeros(q.size)
        e[j] = h
        fd_q = (spacar.dynamics_derivatives(model, q + e, qd, tau)[0] - spacar.dynamics_derivatives(model, q - e, qd, tau)[0]) / (2 * h)
        fd_qd = (spacar.dynamics_derivatives(model, q, qd + e, tau)[0] - spacar.dynamics_derivatives(model, q, qd - e, tau)[0]) / (2 * h)
        assert np.abs(dq[:, j] - fd_q).max() <= 1e-7 * max(1.0, np.abs(dq).max())
        assert np.abs(dqd[:, j] - fd_qd).max() <= 1e-7 * max(1.0, np.abs(dqd).max())


@pytest.mark.parametrize("n", [1, 3, 6])
def test_spatial_hinge_chain_matches_crba_and_aba(n):
    """BEAM links with random directions, HINGE joints about random axes (DYNE e1), full inertia
    tensors on the LAMBDA nodes, BEAM rotary inertia, a rotated ground LAMBDA node."""
    model = models.spatial_chain(n, seed=n, epskin=1e-12)
    assert_matches_pinocchio(model)


def test_spatial_hinge_springs():
    model = models.spatial_chain(3, seed=7, stiffness=2.5, epskin=1e-12)
    assert_matches_pinocchio(model)


def test_spherical_chain_matches_crba_and_aba():
    """No HINGE: shared position nodes are spherical joints; spacar's DOFs are Euler parameters
    (DYNX on the LAMBDA nodes), Pinocchio's are quaternions and relative angular velocities in
    the child frame; T = ∂v_pin/∂q̇ is taken from spacar's DF."""
    model = models.spatial_chain(3, seed=11, joints="spherical", epskin=1e-12)
    assert_matches_pinocchio(model, scale_q=0.15, identity_map=False)


def test_far_states_are_reached_by_continuation():
    """A rigid PLBEAM also satisfies its constraints with the chord reversed; evaluating spacar
    at a state far from the previous one can land there (see evaluate_spacar). The converter
    approaches far states in steps, so the configurations agree (position_error)."""
    model = models.planar_chain(6, rho_a=1.0, epskin=1e-12)
    assert_matches_pinocchio(model, scale_q=math.pi, seed=3)


def test_pinocchio_trajectory_same_integrator():
    """Pinocchio's ABA integrated with spacar's DOP853 (rhs called from C++) against spacar's
    own run: the same ODE in the same coordinates, so they agree to the tolerance."""
    model = models.planar_chain(3, rho_a=1.0, tip_mass=0.2, angle=0.3, eps=1e-11, epskin=1e-12)
    res = spacar.simulate(model.copy())
    pm = sp_pinocchio.build(model)
    q_sp, _ = pm.trajectory(res)
    t, q, v, stats = sp_pinocchio.simulate(model)
    np.testing.assert_allclose(t, res.t)
    assert np.abs(q - q_sp).max() < 1e-8
    assert stats["rhs_evaluations"] > 0
    t2, q2, _, _ = sp_pinocchio.simulate(model, integrator="scipy", rtol=1e-11, atol=1e-14)
    assert np.abs(q2 - q_sp).max() < 1e-8


# --------------------------------------------------------------------------------------------
# exudyn: trajectories
# --------------------------------------------------------------------------------------------

def max_position_difference(r):
    d = np.abs(r["x_spacar"] - r["x_exudyn"])
    assert not np.isnan(r["x_exudyn"]).any()
    return d.max()


def test_double_pendulum_tree_dopri5():
    """Kinematic tree (minimal coordinates) with exudyn's error-controlled DOPRI5 at the same
    tolerance as spacar's DOP853 (rtol 1e-10): positions agree to 1e-8 over 2 s."""
    model = models.planar_chain(2, rho_a=1.0, tip_mass=0.5, angle=0.4, t_end=2.0, n_out=20, eps=1e-10)
    r = sp_exudyn.side_by_side(model, formulation="tree", solver="dopri5", rtol=1e-10, atol=1e-13)
    assert max_position_difference(r) < 1e-8
    np.testing.assert_allclose(r["q_exudyn"][:, 0], r["e_spacar"][:, r["deformation_labels"].index((models.HINGE + 1, 1))], atol=1e-8)


def test_double_pendulum_redundant_generalized_alpha():
    """Redundant coordinates (rigid bodies + revolute joints, a DAE) with exudyn's default
    implicit generalized-α (2nd order, fixed step): differences O(h²) — below 1e-6 at h = 1e-4
    and about four times smaller at h/2."""
    model = models.planar_chain(2, rho_a=1.0, tip_mass=0.5, angle=0.4, t_end=1.0, n_out=10, eps=1e-10)
    d1 = max_position_difference(sp_exudyn.side_by_side(model, step=1e-4))
    d2 = max_position_difference(sp_exudyn.side_by_side(model, step=5e-5))
    assert d1 < 1e-6
    assert d2 < 0.4 * d1


def test_chain_with_springs_tree_and_redundant():
    model = models.planar_chain(3, rho_a=1.0, tip_mass=0.2, stiffness=4.0, damping=0.3, ground_angle=0.3,
                                t_end=1.0, n_out=5, eps=1e-10)
    assert max_position_difference(sp_exudyn.side_by_side(model, formulation="tree", rtol=1e-10)) < 1e-8
    assert max_position_difference(sp_exudyn.side_by_side(model, step=1e-4)) < 1e-6


def test_four_bar_generalized_alpha():
    """A closed loop: only the redundant formulation applies. O(h²) agreement."""
    model = models.four_bar(t_end=1.0, n_out=10, eps=1e-10)
    d1 = max_position_difference(sp_exudyn.side_by_side(model, step=1e-4))
    d2 = max_position_difference(sp_exudyn.side_by_side(model, step=5e-5))
    assert d1 < 2e-6
    assert d2 < 0.4 * d1


def test_spatial_chains():
    model = models.spatial_chain(3, seed=2, eps=1e-10)
    assert max_position_difference(sp_exudyn.side_by_side(model, formulation="tree", rtol=1e-10)) < 1e-8
    assert max_position_difference(sp_exudyn.side_by_side(model, step=1e-4)) < 1e-6
    model = models.spatial_chain(3, seed=2, joints="spherical", eps=1e-10)
    assert max_position_difference(sp_exudyn.side_by_side(model, step=1e-4)) < 1e-6


def chord_deflection(x_of, t_index=slice(None)):
    """Distance of the rod's middle node 6 from the chord 3–8 (the elastic deflection)."""
    p3 = np.column_stack([x_of(3, 1), x_of(3, 2)])
    p6 = np.column_stack([x_of(6, 1), x_of(6, 2)])
    p8 = np.column_stack([x_of(8, 1), x_of(8, 2)])
    c = p8 - p3
    return (c[:, 0] * (p6 - p3)[:, 1] - c[:, 1] * (p6 - p3)[:, 0]) / np.linalg.norm(c, axis=1)


def slider_crank_differences(n_rod, step=2e-4):
    """Largest differences spacar − exudyn over the 5 s: bending deformations of the first two
    rod elements relative to their peak, the rod's elastic mid deflection relative to its peak,
    and the slider position (m)."""
    model = models.slider_crank(n_rod, eps=1e-9, epskin=1e-10)
    r = sp_exudyn.side_by_side(model, step=step)
    res, er = r["spacar_results"], r["exudyn_results"]
    e_rel = [np.abs(res.deformation(e, i) - er.deformation(e, i)).max() / np.abs(res.deformation(e, i)).max()
             for e, i in [(2, 2), (2, 3), (3, 2), (3, 3)]]
    da, db = chord_deflection(res.coordinate), chord_deflection(er.coordinate)
    return (max(e_rel), np.abs(da - db).max() / np.abs(da).max(),
            np.abs(res.coordinate(8, 1) - er.coordinate(8, 1)).max())


def test_flexible_slider_crank_against_ancf():
    """The manual's slider-crank (two PLBEAMs in the rod, axially rigid, bending DYNE) against
    two ANCF cable elements (penalty EA = 1e4 EI/l0², see docs/comparison.md). Same cubic
    interpolation and consistent mass, different bending and axial models, coarse mesh: the
    rod's mid deflection agrees within 6 % of its peak (measured 4.7 %), the element bending
    deformations within 15 % (measured 9–13 %: they carry the lightly damped rod vibration, whose
    phase drifts apart), the slider position within 1e-4 m (measured 3.5e-5)."""
    e_rel, defl_rel, slider = slider_crank_differences(2)
    assert e_rel < 0.15
    assert defl_rel < 0.06
    assert slider < 1e-4


@pytest.mark.slow
def test_flexible_slider_crank_refinement():
    """Four elements per rod in both programs: the differences shrink as both discretisations
    converge (measured: E 5 %, mid deflection 1.1 %, slider 1.1e-5 m)."""
    e_rel, defl_rel, slider = slider_crank_differences(4)
    assert e_rel < 0.08
    assert defl_rel < 0.02
    assert slider < 2e-5


def test_driven_crank_with_acceleration_uses_offset_function():
    """A prescribed rotation with an input acceleration (XDD) becomes a constraint with an
    offset user function; the crank angle follows β0 + ω0 t + ½ α0 t²."""
    model = models.slider_crank(2, t_end=0.5, n_out=5, eps=1e-9, epskin=1e-10)
    model.xdd(2, 1, 0.8)
    r = sp_exudyn.side_by_side(model, step=2e-4)
    t = r["t"]
    np.testing.assert_allclose(r["exudyn_results"].coordinate(2, 1), 1.5 * t + 0.4 * t**2, atol=1e-9)
    assert np.abs(r["exudyn_results"].coordinate(8, 1) - r["spacar_results"].coordinate(8, 1)).max() < 1e-4


# --------------------------------------------------------------------------------------------
# What the converters refuse
# --------------------------------------------------------------------------------------------

def test_unsupported_models_are_named():
    with pytest.raises(UnsupportedModelError, match="closed loop"):
        sp_pinocchio.build(models.four_bar())
    with pytest.raises(UnsupportedModelError, match="flexible"):
        sp_pinocchio.build(models.slider_crank(2))
    with pytest.raises(UnsupportedModelError, match="tree formulation"):
        sp_exudyn.build(models.slider_crank(2), formulation="tree")
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(2, 1.0, 0.0)
    m.fix(1)
    m.fix(2)
    with pytest.raises(UnsupportedModelError, match="PLTRUSS"):
        sp_exudyn.build(m)
    m = models.planar_chain(2)
    m.force(3, 1.0, 0.0)
    with pytest.raises(UnsupportedModelError, match="FORCE"):
        sp_pinocchio.build(m)
    # an UnsupportedModelError is a spacar.InputError
    assert issubclass(UnsupportedModelError, spacar.InputError)


def test_a_diverged_peer_run_reported_as_success_is_refused():
    """Issue 38, finding 2: exudyn returned a diverged state (q ≈ 1e19 on a 20-link chain) while
    reporting success, and the comparison used it. A peer's state that is not finite or has run
    away from the start now raises PeerResultError; a converged run of the same model passes."""
    from spacar.compare import PeerResultError

    peer = sp_exudyn.build(models.spatial_chain(20, t_end=1.0, n_out=1), formulation="tree")
    for step in (0.5, 0.1):  # RK44 far beyond its stability: angles of 1e12 rad, then NaN
        with pytest.raises(PeerResultError, match=r"exudyn's rk44 reported success but returned a diverged state"):
            peer.solve(solver="rk44", step=step, n_out=1)
    assert np.isfinite(peer.solve(solver="rk44", step=0.01, n_out=1).q).all()
