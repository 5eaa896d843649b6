"""Planar kinematics and dynamics against independent references (issue #3, formulation.md
§10.2 and §10.3):

* rigid pendulum: period against the complete elliptic integral;
* energy conservation of a free, undamped, flexible double pendulum under gravity;
* small free vibrations of a PLBEAM cantilever: the consistent-mass frequencies of §10.3 and
  their convergence to the Euler-Bernoulli values, plus one time-domain check;
* four-bar linkage driven by INPUTX against the closed-form (loop-closure) solution;
* the errors of mechanisms that cannot be analysed (KinematicsError, SingularMassError).

The references are computed here from textbook formulas; from the core only the public results
and ``spacar._core.Simulation`` (``evaluate`` and its ``data``: x, xd, e, M, Mbar, qdd) are used.
"""
from __future__ import annotations

import math
import re
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize
import scipy.special

import spacar
from support.paths import EXAMPLES
from support.simulation import assembled

G = 9.81


def assert_finite(res):
    """A successful run never returns NaN or infinity in any result array."""
    for name in ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma"):
        arr = getattr(res, name)
        assert np.isfinite(arr).all(), f"non-finite values in results.{name}"


def dof_state(sim, res, k):
    """The DOF vector q = (x^d, e^d) and its rate at output k of ``res`` (same model)."""
    s = sim.system
    q = np.concatenate([res.x[k, s.x_dyn], res.e[k, s.e_dyn]])
    qd = np.concatenate([res.xd[k, s.x_dyn], res.ed[k, s.e_dyn]])
    return q, qd


def stiffness_by_differences(sim, q0, h=1e-6):
    """K = -Mbar dqdd/dq at (q0, qd = 0) by central differences with one Richardson
    extrapolation (steps h and h/2): the truncation error of a plain central difference is
    amplified by the poor conditioning of Mbar in relative bending coordinates (8 elements:
    cond ~ 5e5), and would shift the lowest frequency by ~2e-6."""
    n = len(q0)
    qd = np.zeros(n)

    def jac(step):
        J = np.empty((n, n))
        for j in range(n):
            dq = np.zeros(n)
            dq[j] = step
            sim.evaluate(0.0, q0 + dq, qd)
            plus = np.array(sim.data.qdd)
            sim.evaluate(0.0, q0 - dq, qd)
            J[:, j] = (plus - np.array(sim.data.qdd)) / (2 * step)
        return J

    J = (4 * jac(h / 2) - jac(h)) / 3
    sim.evaluate(0.0, q0, qd)
    Mbar = np.array(sim.data.Mbar)
    return -Mbar @ J, Mbar


# --------------------------------------------------------------------------------------------
# Rigid pendulum
# --------------------------------------------------------------------------------------------

def pendulum(theta0, m_tip, rho_a, L=1.0, eps=1e-10):
    """PLBEAM from the fixed node 1 to node 3, released at rest at theta0 from the downward
    vertical; DOF: the rotation beta of node 2 (0 at release)."""
    model = spacar.Model()
    model.plbeam(1, 1, 2, 3, 4)
    model.x(3, L * math.sin(theta0), -L * math.cos(theta0))
    model.fix(1)
    if m_tip:
        model.mass(3, m_tip)
    if rho_a:
        model.emass(1, rho_a)
    model.gravity(0.0, -G)
    model.dynx(2, 1)
    model.epsint(eps)
    model.epsind(eps)
    model.epskin(1e-12)
    return model


def pendulum_period(theta0, m_tip, rho_a, L=1.0):
    inertia = m_tip * L**2 + rho_a * L**3 / 3          # about the pivot
    static = m_tip * L + 0.5 * rho_a * L**2            # first moment of mass
    k = math.sin(theta0 / 2)
    return 4 * math.sqrt(inertia / (G * static)) * scipy.special.ellipk(k * k), inertia, static


MASS_MODELS = {"tip MASS": (1.0, 0.0), "EMASS only": (0.0, 2.0), "MASS and EMASS": (0.5, 2.0)}


@pytest.mark.parametrize("theta0", [0.1, 1.0, 2.0, 3.0])
@pytest.mark.parametrize("mass_model", list(MASS_MODELS))
def test_pendulum_period_elliptic_integral(theta0, mass_model):
    m_tip, rho_a = MASS_MODELS[mass_model]
    T, inertia, static = pendulum_period(theta0, m_tip, rho_a)
    model = pendulum(theta0, m_tip, rho_a)
    model.timestep(4, T)  # quarter periods
    res = model.run()
    assert_finite(res)
    j = res.coordinate_index(2, 1)
    beta, beta_d, beta_dd = res.x[:, j], res.xd[:, j], res.xdd[:, j]
    # The swing angle is theta0 + beta. Period: the velocity vanishes again at t = T; the zero
    # of the velocity near T is at T - beta_d / beta_dd (one Newton step, error O(dT^2)).
    period_error = -beta_d[-1] / beta_dd[-1]
    assert abs(period_error) / T < 1e-8
    assert abs(beta[-1]) < 1e-8 * theta0 + 1e-12
    # Half period: at rest at -theta0; quarter periods: through the bottom at the energy speed.
    assert beta[2] == pytest.approx(-2 * theta0, rel=1e-8)
    assert abs(beta_d[2]) < 1e-8 * abs(beta_dd[2]) * T
    omega_bottom = math.sqrt(2 * G * static * (1 - math.cos(theta0)) / inertia)
    assert beta[1] == pytest.approx(-theta0, rel=1e-8)
    assert beta[3] == pytest.approx(-theta0, rel=1e-8)
    assert beta_d[1] == pytest.approx(-omega_bottom, rel=1e-8)
    assert beta_d[3] == pytest.approx(omega_bottom, rel=1e-8)
    # Initial angular acceleration from the moment of gravity about the pivot.
    assert beta_dd[0] == pytest.approx(-G * static * math.sin(theta0) / inertia, rel=1e-10)


def test_pendulum_many_periods():
    """Ten periods of a large swing: the period error does not accumulate beyond 1e-8 per period."""
    theta0, (m_tip, rho_a) = 2.5, MASS_MODELS["MASS and EMASS"]
    T, _, _ = pendulum_period(theta0, m_tip, rho_a)
    model = pendulum(theta0, m_tip, rho_a)
    model.timestep(10, 10 * T)
    res = model.run()
    assert_finite(res)
    j = res.coordinate_index(2, 1)
    drift = -res.xd[:, j] / res.xdd[:, j]          # time to the turning point nearest t = kT
    assert np.all(np.abs(drift[1:]) < 1e-8 * T * np.arange(1, 11))
    assert np.all(np.abs(res.x[:, j]) < 1e-7)


# --------------------------------------------------------------------------------------------
# Energy of a free, undamped, flexible system
# --------------------------------------------------------------------------------------------

DP_L, DP_RHOA, DP_EI, DP_TIP = 1.0, 1.0, 20.0, 0.3
DP_ANGLE2 = 0.5  # initial chord angle of the second link


def double_pendulum(hanging=False, eps=1e-10):
    """Two flexible PLBEAMs (axially rigid, bending DYNE) joined by a hinge at node 3; the first
    hinged at the fixed node 1; a tip MASS at node 6; gravity. Released from an inclined,
    pre-bent state with a spin of the second link (or, hanging=True: the straight hanging
    equilibrium)."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 5, 6, 7)
    if hanging:
        m.x(3, 0.0, -DP_L)
        m.x(6, 0.0, -2 * DP_L)
    else:
        m.x(3, DP_L, 0.0)
        m.x(6, DP_L + DP_L * math.cos(DP_ANGLE2), DP_L * math.sin(DP_ANGLE2))
    m.fix(1)
    m.dynx(2, 1)
    m.dynx(5, 1)
    for k in (1, 2):
        m.dyne(k, 2, 3)
        m.emass(k, DP_RHOA)
        m.estiff(k, 0.0, DP_EI)
    m.mass(6, DP_TIP)
    m.gravity(0.0, -G)
    m.epsint(eps)
    m.epsind(eps)
    m.epskin(1e-12)
    if not hanging:
        m.e(1, 2, 0.01)
        m.e(2, 3, -0.01)
        m.xd(5, 1, 1.0)
    return m


# (element, p, beta_p, q, beta_q, reference chord angle alpha0) of the released double pendulum
DP_ELEMENTS = [(1, 1, 2, 3, 4, 0.0), (2, 3, 5, 6, 7, DP_ANGLE2)]


def energies(model, res, elements, l0, rho_a, ei, point_masses, gravity):
    """(T, V_elastic, V_gravity) at every output time, from the formulas of formulation.md
    §3.2-§4.2: T = 1/2 xd' M xd (M from Simulation.evaluate), V_e = 1/2 e' S e with the PLBEAM
    bending stiffness (EI/l0^3)[[4, -2], [-2, 4]] (axial deformations rigid), V_g = -sum m g.x
    - sum rhoA l0 g.(x_p/2 + (l0/12) t_p + x_q/2 - (l0/12) t_q), t = (cos, sin)(alpha0 + beta)."""
    sim = assembled(model)
    labels = [tuple(lbl) for lbl in sim.system.coord_label]
    dlabels = [tuple(lbl) for lbl in sim.system.def_label]
    g = np.asarray(gravity, dtype=float)
    S = ei / l0**3 * np.array([[4.0, -2.0], [-2.0, 4.0]])
    out = []
    for k, t in enumerate(res.t):
        q, qd = dof_state(sim, res, k)
        sim.evaluate(t, q, qd)
        d = sim.data
        x, xd, e, M = np.array(d.x), np.array(d.xd), np.array(d.e), np.array(d.M)

        def node(n, dim=2):
            return x[[labels.index((n, i)) for i in range(1, dim + 1)]]

        T = 0.5 * xd @ M @ xd
        Ve = 0.0
        Vg = 0.0
        for (el, p, bp, qn, bq, alpha0) in elements:
            eb = e[[dlabels.index((el, 2)), dlabels.index((el, 3))]]
            Ve += 0.5 * eb @ S @ eb
            phi_p, phi_q = alpha0 + node(bp, 1)[0], alpha0 + node(bq, 1)[0]
            tp = np.array([math.cos(phi_p), math.sin(phi_p)])
            tq = np.array([math.cos(phi_q), math.sin(phi_q)])
            Vg -= rho_a * l0 * g @ (0.5 * node(p) + l0 / 12 * tp + 0.5 * node(qn) - l0 / 12 * tq)
        for n, mass in point_masses.items():
            Vg -= mass * g @ node(n)
        out.append((T, Ve, Vg))
    return np.array(out)


def lowest_elastic_frequency():
    """Frequencies of the linearized double pendulum about the hanging equilibrium; the two
    lowest are the swinging modes, the third is the lowest elastic mode."""
    model = double_pendulum(hanging=True)
    sim = assembled(model)
    K, Mbar = stiffness_by_differences(sim, np.zeros(sim.system.n_dof))
    w2 = np.sort(scipy.linalg.eigvals(K, Mbar).real)
    assert np.all(w2 > 0)
    omega = np.sqrt(w2)
    assert omega[2] > 5 * omega[1]  # the elastic modes are well separated from the swinging ones
    return omega[2]


@pytest.mark.parametrize("eps", [1e-10, 1e-7])
def test_energy_conservation_flexible_double_pendulum(eps):
    omega_e = lowest_elastic_frequency()
    t_end = 10 * 2 * math.pi / omega_e
    model = double_pendulum(eps=eps)
    probe = model.copy()
    model.timestep(200, t_end)
    res = model.run()
    assert_finite(res)
    E = energies(probe, res, DP_ELEMENTS, DP_L, DP_RHOA, DP_EI, {6: DP_TIP}, (0.0, -G))
    total = E.sum(axis=1)
    scale = E[:, 0].max()                       # the largest kinetic energy of the motion
    # The motion is large and elastic: energy is really exchanged between all three forms.
    assert np.ptp(E[:, 0]) > 0.5 * scale and np.ptp(E[:, 2]) > 0.5 * scale
    assert E[:, 1].max() > 1e-3 * scale
    drift = np.abs(total - total[0]).max() / scale
    assert drift < 1e-6
    assert drift < 10 * eps  # formulation.md §10.2: ~10 EPSINT


def test_energy_conservation_flexible_double_pendulum_long():
    """20 s (about 180 periods of the lowest elastic mode) at EPSINT = EPSIND = 1e-9."""
    model = double_pendulum(eps=1e-9)
    probe = model.copy()
    model.timestep(500, 20.0)
    res = model.run()
    assert_finite(res)
    E = energies(probe, res, DP_ELEMENTS, DP_L, DP_RHOA, DP_EI, {6: DP_TIP}, (0.0, -G))
    total = E.sum(axis=1)
    assert np.abs(total - total[0]).max() / E[:, 0].max() < 1e-6


# --------------------------------------------------------------------------------------------
# Cantilever frequencies (formulation.md §10.3)
# --------------------------------------------------------------------------------------------

# formulation.md §10.3: sqrt of the eigenvalues of the consistent-mass PLBEAM cantilever
CANTILEVER_TABLE = {
    1: [3.532732, 34.80689],
    2: [3.517715, 22.22147, 75.15708],
    4: [3.516130, 22.06017, 62.17489],
    8: [3.516023, 22.03625, 61.73474],
}


def euler_bernoulli_cantilever(count=3):
    """Exact omega_i for EI = rhoA = L = 1: (beta_i L)^2 with cos(bL) cosh(bL) = -1."""
    f = lambda b: math.cos(b) * math.cosh(b) + 1.0  # noqa: E731
    brackets = [(1.0, 3.0), (4.0, 6.0), (7.0, 9.0), (10.0, 12.0)]
    return [scipy.optimize.brentq(f, a, b, xtol=1e-15) ** 2 for a, b in brackets[:count]]


def cantilever(n, ei=1.0, rho_a=1.0, L=1.0):
    """n equal PLBEAMs along x, clamped at node 1 (x, y) and node 2 (beta), e1 rigid, bending
    deformations DYNE."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, L * k / n, 0.0)
        m.emass(k, rho_a)
        m.estiff(k, 0.0, ei)
        m.dyne(k, 2, 3)
    m.fix(1)
    m.fix(2)
    m.epskin(1e-13)
    return m


def cantilever_modes(n):
    model = cantilever(n)
    sim = assembled(model)
    K, Mbar = stiffness_by_differences(sim, np.zeros(sim.system.n_dof))
    assert np.abs(K - K.T).max() < 1e-9 * np.abs(K).max()
    w2, V = scipy.linalg.eigh(0.5 * (K + K.T), Mbar)
    return np.sqrt(w2), V, Mbar, sim


def test_euler_bernoulli_reference():
    exact = euler_bernoulli_cantilever()
    assert exact == pytest.approx([1.8751040687**2, 4.6940911330**2, 7.8547574382**2], rel=1e-10)
    assert exact == pytest.approx([3.516015, 22.03449, 61.69721], abs=1e-5)


@pytest.mark.parametrize("n", sorted(CANTILEVER_TABLE))
def test_cantilever_frequencies_table(n):
    omega, _, _, _ = cantilever_modes(n)
    table = CANTILEVER_TABLE[n]
    assert omega[: len(table)] == pytest.approx(table, rel=1e-5)
    assert len(omega) == 2 * n


def test_cantilever_frequencies_converge_to_euler_bernoulli():
    exact = np.array(euler_bernoulli_cantilever())
    errors = {}
    for n in (1, 2, 4, 8):
        omega, _, _, _ = cantilever_modes(n)
        m = min(3, len(omega))
        err = omega[:m] / exact[:m] - 1
        assert np.all(err > 0)  # a consistent-mass model is stiffer than the continuum
        errors[n] = err
    # Every frequency improves with every halving of the elements ...
    for a, b in ((1, 2), (2, 4), (4, 8)):
        m = len(errors[a])
        assert np.all(errors[b][:m] < errors[a] / 4)
    # ... and on the finest halving at the asymptotic rate h^4 of cubic Hermite elements
    # (error ratio 16; measured 15.7, 14.6, 12.7 for the first three frequencies).
    assert np.all((errors[4] / errors[8] > 12) & (errors[4] / errors[8] < 20))
    assert errors[8] == pytest.approx([2.08e-6, 8.00e-5, 6.08e-4], rel=0.01)


def test_cantilever_first_mode_time_domain():
    """A small initial deflection in the first mode shape (8 elements) oscillates in that shape
    with the period 2 pi / omega_1 of the linearized equations."""
    omega, V, Mbar, sim = cantilever_modes(8)
    w1 = omega[0]
    T1 = 2 * math.pi / w1
    v = V[:, 0] / np.abs(V[:, 0]).max()
    amplitude = 1e-5                     # bending deformations in length units, l0 = 0.125
    q0 = amplitude * v
    model = cantilever(8)
    labels = [tuple(sim.system.def_label[k]) for k in sim.system.e_dyn]
    for (el, i), value in zip(labels, q0):
        model.e(el, i, value)
    model.epsint(1e-10)
    model.epsind(1e-10)
    model.timestep(4, T1)
    res = model.run()
    assert_finite(res)
    cols = [res.deformation_index(el, i) for el, i in labels]
    q, qd = res.e[:, cols], res.ed[:, cols]
    eta, eta_d = q @ Mbar @ v, qd @ Mbar @ v   # modal coordinate (Mbar-weighted projection)
    # Period: the modal velocity vanishes at t = T1 (turning point estimate as for the pendulum).
    period_error = eta_d[-1] / (w1**2 * eta[0])
    assert abs(period_error) / T1 < 1e-7       # measured 2e-9
    assert eta / eta[0] == pytest.approx([1, 0, -1, 0, 1], abs=1e-5)
    # It stays in the mode shape.
    assert np.abs(q[2] + q0).max() < 1e-6 * amplitude
    assert np.abs(q[4] - q0).max() < 1e-6 * amplitude


# --------------------------------------------------------------------------------------------
# Four-bar linkage driven by INPUTX
# --------------------------------------------------------------------------------------------

FB_A, FB_B, FB_C, FB_D = 0.1, 0.35, 0.3, 0.4   # crank, coupler, rocker, ground (Grashof crank-rocker)


def fourbar_closed_form(theta, theta_d, theta_dd, branch=1, dims=(FB_A, FB_B, FB_C, FB_D)):
    """Crank A(0,0)-B, coupler B-C, rocker D(d,0)-C. Positions by intersecting the circles about
    B and D; rates by differentiating the loop equation a e^{i theta} + b e^{i phi} = d +
    c e^{i psi} once and twice (two linear equations in the coupler and rocker rates)."""
    a, b, c, d = dims
    B = np.array([a * math.cos(theta), a * math.sin(theta)])
    D = np.array([d, 0.0])
    u = D - B
    f = math.hypot(*u)
    uh = u / f
    along = (b * b - c * c + f * f) / (2 * f)
    C = B + along * uh + branch * math.sqrt(b * b - along * along) * np.array([-uh[1], uh[0]])
    phi = math.atan2(C[1] - B[1], C[0] - B[0])
    psi = math.atan2(C[1] - D[1], C[0] - D[0])
    A = np.array([[-b * math.sin(phi), c * math.sin(psi)], [b * math.cos(phi), -c * math.cos(psi)]])
    rhs1 = np.array([a * theta_d * math.sin(theta), -a * theta_d * math.cos(theta)])
    phi_d, psi_d = np.linalg.solve(A, rhs1)
    rhs2 = np.array([
        a * theta_dd * math.sin(theta) + a * theta_d**2 * math.cos(theta)
        + b * phi_d**2 * math.cos(phi) - c * psi_d**2 * math.cos(psi),
        -a * theta_dd * math.cos(theta) + a * theta_d**2 * math.sin(theta)
        + b * phi_d**2 * math.sin(phi) - c * psi_d**2 * math.sin(psi),
    ])
    phi_dd, psi_dd = np.linalg.solve(A, rhs2)
    return dict(B=B, C=C, phi=phi, psi=psi, phi_d=phi_d, psi_d=psi_d, phi_dd=phi_dd, psi_dd=psi_dd)


def fourbar(theta0, branch=1, dims=(FB_A, FB_B, FB_C, FB_D), input_=True):
    """Rigid PLBEAMs: crank 1 (nodes 1-4), coupler 2 (3, 5, 6, 7), rocker 3 (8, 9, 6, 10); ground
    nodes 1 and 8 fixed; the crank rotation beta_2 is the input."""
    ref = fourbar_closed_form(theta0, 0.0, 0.0, branch, dims)
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 5, 6, 7)
    m.plbeam(3, 8, 9, 6, 10)
    m.x(3, *ref["B"])
    m.x(6, *ref["C"])
    m.x(8, dims[3], 0.0)
    m.fix(1)
    m.fix(8)
    if input_:
        m.inputx(2, 1)
    return m, ref


def wrap(angle):
    return (np.asarray(angle) + math.pi) % (2 * math.pi) - math.pi


@pytest.mark.parametrize("branch", [1, -1])
@pytest.mark.parametrize("theta0, speed, accel", [(0.3, 2.0, 0.0), (0.3, 2.0, 0.5), (-1.0, -3.0, 1.0)])
def test_fourbar_against_closed_form(branch, theta0, speed, accel):
    model, ref0 = fourbar(theta0, branch)
    model.xd(2, 1, speed)
    model.xdd(2, 1, accel)
    model.epskin(1e-12)
    model.timestep(50, 5.0)   # more than one crank revolution
    res = model.run()
    assert_finite(res)
    assert res.stats["rhs_evaluations"] == 0  # a kinematic analysis: no integration
    jb, jr = res.coordinate_index(2, 1), res.coordinate_index(9, 1)
    psi0 = ref0["psi"]                # reference chord angle of the rocker = its initial angle
    samples = speed * np.linspace(0, 5, 1001) + 0.5 * accel * np.linspace(0, 5, 1001) ** 2
    assert np.abs(np.diff(samples)).sum() > 2 * math.pi   # more than one crank revolution
    for k, t in enumerate(res.t):
        theta = theta0 + speed * t + 0.5 * accel * t * t
        theta_d = speed + accel * t
        ref = fourbar_closed_form(theta, theta_d, accel, branch)
        assert res.x[k, jb] == pytest.approx(theta - theta0, abs=1e-12)
        assert res.xd[k, jb] == pytest.approx(theta_d, abs=1e-12)
        assert res.xdd[k, jb] == accel
        assert abs(wrap(psi0 + res.x[k, jr] - ref["psi"])) < 1e-8
        assert res.xd[k, jr] == pytest.approx(ref["psi_d"], abs=1e-8 * (1 + abs(ref["psi_d"])))
        assert res.xdd[k, jr] == pytest.approx(ref["psi_dd"], abs=1e-8 * (1 + abs(ref["psi_dd"])))
        assert res.node(6).x[k] == pytest.approx(ref["C"], abs=1e-10)
        # coupler: node 5 carries its rotation
        assert abs(wrap(ref0["phi"] + res.coordinate(5, 1)[k] - ref["phi"])) < 1e-8
        assert res.node(5).xd[k, 0] == pytest.approx(ref["phi_d"], abs=1e-8 * (1 + abs(ref["phi_d"])))
        assert res.node(5).xdd[k, 0] == pytest.approx(ref["phi_dd"], abs=1e-8 * (1 + abs(ref["phi_dd"])))
    # All deformations stay rigid.
    assert np.abs(res.e).max() < 1e-12


# --------------------------------------------------------------------------------------------
# Mechanisms that cannot be analysed
# --------------------------------------------------------------------------------------------

def expect_error(model, kind):
    with pytest.raises(kind) as info:
        model.run()
    message = str(info.value)
    assert "nan" not in message.lower() and "inf " not in message.lower()
    return message


def test_underconstrained_fourbar_without_input():
    model, _ = fourbar(0.3, input_=False)
    model.timestep(10, 1.0)
    message = expect_error(model, spacar.KinematicsError)
    assert "9 constraint equations" in message and "10 calculable coordinates" in message
    assert "under-constrained by 1" in message
    assert "undetermined coordinates" in message
    assert "node 2 component 1" in message  # the crank angle: needs INPUTX, DYNX or FIX


def test_overconstrained_fourbar():
    """Crank angle fixed and a rigid truss B-D added: the truss repeats what the crank already
    determines."""
    model, _ = fourbar(0.3, input_=False)
    model.fix(2, 1)
    model.pltruss(4, 3, 8)
    model.timestep(10, 1.0)
    message = expect_error(model, spacar.KinematicsError)
    assert "over-constrained by 1" in message
    assert "redundant constraints" in message
    assert "element 4 (PLTRUSS) deformation 1" in message
    assert "element 1 (PLBEAM) deformation 1" in message


def test_square_but_singular_block():
    """Two rigid trusses in line between fixed end points: as many equations as unknowns, but
    one equation is redundant and the transverse position of the middle node undetermined."""
    model = spacar.Model()
    model.pltruss(1, 1, 2)
    model.pltruss(2, 2, 3)
    model.x(2, 1.0, 0.0)
    model.x(3, 2.0, 0.0)
    model.fix(1)
    model.fix(3)
    model.timestep(1, 1.0)
    message = expect_error(model, spacar.KinematicsError)
    assert "singular" in message
    assert "element 1 (PLTRUSS) deformation 1" in message and "element 2 (PLTRUSS) deformation 1" in message
    assert "node 2 component 2" in message


def test_input_to_unreachable_position():
    """A non-Grashof four-bar (a = 0.3, b = 0.35, c = 0.3, d = 0.4): the crank cannot pass
    theta = acos(-0.71875) = 2.3729; driven from 0.3 at 1 rad/s the output time t = 2.1 is
    beyond reach."""
    dims = (0.3, 0.35, 0.3, 0.4)
    model, _ = fourbar(0.3, dims=dims)
    model.xd(2, 1, 1.0)
    model.timestep(50, 5.0)
    message = expect_error(model, spacar.KinematicsError)
    assert "did not converge" in message and "t = 2.1 " in message
    assert "residual" in message and "element" in message and "PLBEAM" in message


def test_dynamic_mechanism_reaching_a_dead_point():
    """The same linkage with the crank angle as a DOF, spun towards its limit position, where
    coupler and rocker are stretched in line: beyond it the kinematics has no solution, the step
    size collapses, and the failure is a KinematicsError at the time the crank reaches the limit,
    not a bare integration failure (formulation.md §2.2). Only the crank has mass, so it turns at
    constant speed and arrives with that speed: θ_lim from |B − D| = b + c. (With mass on the
    coupler and rocker the reduced mass grows without bound there and the crank stops and turns
    back exactly at the limit; that passage is ill-conditioned in the crank angle, the
    equations of motion being 0/0 there, and a run may get through it or fail.)"""
    a, b, c, d = dims = (0.3, 0.35, 0.3, 0.4)
    theta0, omega = 0.3, 5.0
    model, _ = fourbar(theta0, dims=dims, input_=False)
    model.dynx(2, 1)
    model.xd(2, 1, omega)
    model.emass(1, 1.0)
    model.timestep(50, 5.0)
    message = expect_error(model, spacar.KinematicsError)
    theta_lim = math.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d))
    t_lim = (theta_lim - theta0) / omega
    failed_at = float(re.search(r"at t = ([0-9.e+-]+)", message).group(1))
    # Within 0.5 mrad of the limit: the coupler and rocker move like the square root of the
    # distance to it, which defeats the continuity check of the steps just before.
    assert abs(failed_at - t_lim) < 1e-4
    assert "singular configuration" in message or "residual" in message


def test_singular_mass_dyne_without_inertia():
    """Two-element cantilever with mass only on element 1: both bending DOFs of element 2 move
    only its massless nodes (a two-dimensional null space of Mbar): both are named, and none of
    the DOFs of element 1."""
    model = cantilever(2)
    model.emass(2, 0.0)
    model.timestep(10, 1.0)
    message = expect_error(model, spacar.SingularMassError)
    assert "DYNE element 2 (PLBEAM) deformation 2" in message
    assert "DYNE element 2 (PLBEAM) deformation 3" in message
    assert "element 1" not in message


def test_singular_mass_single_dof_of_several():
    """The manual's slider-crank without the mass of the rod end (EMASS 3 and MASS 8 zero): of
    the four bending DOFs only the end rotation e3 of element 3 moves nothing (e2 of element 3
    turns the chord and so moves the massive element 2)."""
    model = spacar.read(str(EXAMPLES / "slidercrank.dat"))
    model.emass(3, 0.0)
    model.mass(8, 0.0)
    message = expect_error(model, spacar.SingularMassError)
    assert "DYNE element 3 (PLBEAM) deformation 3" in message
    for other in ("element 2 (PLBEAM) deformation", "element 3 (PLBEAM) deformation 2"):
        assert other not in message


def test_singular_mass_dynx_without_inertia():
    model = pendulum(1.0, 0.0, 0.0)
    model.timestep(10, 1.0)
    message = expect_error(model, spacar.SingularMassError)
    assert "DYNX node 2 component 1" in message


def test_cli_reports_errors_without_results(tmp_path):
    """`spacar run` on a mechanism that cannot be assembled: exit status 1, the error on
    standard error, no dump and no NaN on standard output, and it does not hang."""
    path = tmp_path / "collinear.dat"
    path.write_text("PLTRUSS 1 1 2\nPLTRUSS 2 2 3\nX 2 1. 0.\nX 3 2. 0.\nFIX 1\nFIX 3\nTIMESTEP 1 1.\nEND\n")
    proc = subprocess.run([sys.executable, "-m", "spacar", "run", str(path)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1
    assert "KinematicsError" in proc.stderr and "element 1 (PLTRUSS) deformation 1" in proc.stderr
    assert "nan" not in (proc.stdout + proc.stderr).lower()
    assert not any(line.strip() == "END" for line in proc.stdout.splitlines())
