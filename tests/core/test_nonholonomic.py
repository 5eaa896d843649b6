"""Rolling, belts and nonholonomic constraints at system level (issue #6; formulation.md §5,
§6, §7.3, §10.6), each against an independent reference:

* a planar wheel (PLWHEEL, slips ENHC) rolling down an incline: a = g sin α / (1 + I/(m r²)),
  the contact point at rest;
* a belt drive (PLBELT): speed ratio r1/r2 of a rigid belt; power balance of an elastic belt with
  mass between the driving reaction and d/dt of the kinetic and strain energy of the whole drive;
* a rolling disc (WHEEL) in steady circular motion: the steady-motion condition between lean
  angle, spin and radius, derived below, kept over several revolutions;
* a disc rolling in a spherical bowl (WHEEL on a quadratic surface): in its vertical plane
  through the bowl's centre, the pendulum equation (R − r)(1 + I_a/(m r²)) θ̈ = −g sin θ solved
  independently; in a general 3-D motion, energy conserved and the contact point at rest;
* the Whipple bicycle of Meijaard et al. (2007), examples/bicycle.dat: M, C1, K0, K2, the
  eigenvalues at 0–10 m/s, the weave and capsize speeds;
* a planar cart (two PLWHEELs on a rigid body): turning radius at constant steer; released
  slips with creep damping: dissipated energy = creep power; the linearized equations' zero
  eigenvalues for kinematic coordinates that do not appear in R (§7.3);
* ENHC input errors; dump and restart of nonholonomic models; the CLI path of the bicycle.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson, solve_ivp
from scipy.optimize import brentq

import spacar
from spacar import _testing
from support.paths import EXAMPLES
from support.spatial_models import R_, body_angular_velocity

BICYCLE = EXAMPLES / "bicycle.dat"

TIGHT = dict(epsint=1e-12, epsind=1e-12, epskin=1e-12)


def tight(m, epsint=1e-12, epsind=1e-12, epskin=1e-12):
    m.epsint(epsint)
    m.epsind(epsind)
    m.epskin(epskin)
    return m


def t_of(a):
    return np.array([math.cos(a), math.sin(a)])


# ---------------------------------------------------------------------------------------------
# Planar wheel rolling down an incline
# ---------------------------------------------------------------------------------------------

def incline_wheel(alpha, gdir, heading, m=2.0, r=0.4, I=0.11, T=2.0, n=20, epskin=1e-12):
    """The plane of the model is the incline: in-plane gravity g sin α along t(gdir). PLBEAR 1
    from fixed ground nodes (1, 2) to the wheel centre 3 and heading 4: its e1, e2 (x, y) are
    the kinematic coordinates of the slips of PLWHEEL 2 (ENHC), e3 (heading) stays fixed at
    `heading` (E). Spin 5: DYNX. Axle (0, 1) turned by the heading: rolling direction
    t = (cos h, sin h)."""
    M = spacar.Model()
    M.plbear(1, 1, 2, 3, 4)
    M.plwheel(2, 3, 4, 5, r, 0.0, 1.0)
    M.xy(1, 0.2, -0.1)
    M.xy(3, 0.2, -0.1)
    M.fix(1)
    M.fix(2)
    M.e(1, 3, heading)
    M.enhc(2, 1, 1, 1)
    M.enhc(2, 2, 1, 2)
    M.dynx(5)
    M.mass(3, m)
    M.mass(5, I)
    g = 9.81 * math.sin(alpha)
    M.gravity(g * math.cos(gdir), g * math.sin(gdir))
    M.timestep(n, T)
    return tight(M, epskin=epskin)


@pytest.mark.parametrize("alpha, gdir, heading", [(0.3, 0.0, 0.0), (0.5, 0.4, -0.7), (0.2, 2.0, 2.5)])
def test_planar_wheel_rolling_down_an_incline(alpha, gdir, heading):
    """Centre acceleration (g sin α) cos(gdir − h) / (1 + I/(m r²)) along the rolling direction
    t, none across it, to 1e-9 relative; position ½ a t² t; spin rate v/r."""
    m, r, I = 2.0, 0.4, 0.11
    res = incline_wheel(alpha, gdir, heading, m, r, I).run()
    t = t_of(heading)
    g_along = 9.81 * math.sin(alpha) * math.cos(gdir - heading)
    a = g_along / (1 + I / (m * r * r))
    acc = res.node(3).xdd
    assert np.max(np.abs(acc - a * t)) < 1e-9 * abs(a)
    x0 = np.array([0.2, -0.1])
    assert np.max(np.abs(res.node(3).x - x0 - 0.5 * a * res.t[:, None] ** 2 * t)) < 1e-9
    np.testing.assert_allclose(res.node(5).xd[:, 0], a * res.t / r, rtol=0, atol=1e-9)
    np.testing.assert_allclose(res.node(4).x[:, 0], heading, atol=1e-12)


def test_rolling_wheel_contact_point_does_not_slip():
    """The material velocity of the contact point, v_c = ẋ_p + ω × (−r k) with ω = β̇_spin a
    (3-D, the wheel standing on the incline), vanishes to EPSKIN at every output time; the slip
    rates are zero and the nonholonomic deformations keep their value."""
    epskin = 1e-5  # the default: the velocity constraints hold exactly, whatever EPSKIN
    heading, r = 0.6, 0.4
    res = incline_wheel(0.4, 1.0, heading, r=r, n=40, epskin=epskin).run()
    a = np.array([-math.sin(heading), math.cos(heading), 0.0])  # axle R(h)(0, 1)
    for i in range(len(res.t)):
        xd = np.array([*res.node(3).xd[i], 0.0])
        vc = xd + np.cross(res.node(5).xd[i, 0] * a, [0.0, 0.0, -r])
        assert np.max(np.abs(vc)) < epskin
        assert np.max(np.abs(vc)) < 1e-13 * max(1.0, np.abs(xd).max())
    assert np.max(np.abs(res.element(2).ed)) < 1e-13
    assert np.max(np.abs(res.element(2).e)) == 0.0


# ---------------------------------------------------------------------------------------------
# Belt drive
# ---------------------------------------------------------------------------------------------

R1, R2, EA, I1, I2, LOAD = 0.1, 0.25, 2000.0, 0.01, 0.03, -0.5
RHOA, A1, A2 = 0.5, 4.0, 5.0


def belt_drive(rigid, n=50, T=0.5, mass=True):
    """PLBELT 1 between fixed centres; pulley 1 (node 2) driven by INPUTX with XD 3, XDD 5;
    pulley 2 (node 4) with inertia I2 and a load torque. Rigid belt: e1 fixed, pulley 2
    calculable. Elastic: e1 RLSE with ESTIFF EA, pulley 2 DYNX. EMASS ρA a1 a2."""
    M = spacar.Model()
    M.plbelt(1, 1, 2, 3, 4, R1, R2)
    M.xy(1, 0.0, 0.0)
    M.xy(3, 0.8 * math.cos(0.3), 0.8 * math.sin(0.3))
    M.fix(1)
    M.fix(3)
    M.inputx(2)
    M.xd(2, 1, 3.0)
    M.xdd(2, 1, 5.0)
    if not rigid:
        M.rlse(1)
        M.estiff(1, EA)
        M.dynx(4)
    if mass:
        M.emass(1, RHOA, A1, A2)
    M.mass(2, I1)
    M.mass(4, I2)
    M.force(4, LOAD)
    M.timestep(n, T)
    M.forcemode(1)
    return tight(M)


def belt_kernel(model):
    el = model.elements[1]
    return _testing.element_kernel("PLBELT", params=list(el.params), l0=el.l0, lgeomy=list(el.lgeomy),
                                   emass=list(el.emass))


def test_rigid_belt_speed_ratio_is_exact():
    """e1 rigid between fixed centres: β̇2/β̇1 = r1/r2 and β2 − β2(0) = (r1/r2)(β1 − β1(0)) at every
    output time, to round-off, while pulley 1 accelerates."""
    res = belt_drive(rigid=True).run()
    b1, b2 = res.coordinate(2, 1), res.coordinate(4, 1)
    w1, w2 = res.xd[:, res.coordinate_index(2, 1)], res.xd[:, res.coordinate_index(4, 1)]
    assert np.max(np.abs(w2 / w1 - R1 / R2)) < 1e-15
    assert np.max(np.abs((b2 - b2[0]) - R1 / R2 * (b1 - b1[0]))) < 1e-14
    assert np.max(np.abs(res.deformation(1, 1))) < 1e-14


def power_balance(model, res):
    """(input power + load power, d/dt(T + V_e)) at each output time. The input power is the
    reaction on the driven coordinate (FORCEMODE 1) times its rate. dT/dt is the derivative of
    the kinetic energy along the motion, d/ds T(x + sẋ, ẋ + sẍ), by Richardson-extrapolated
    central differences of the belt's kinetic energy (pulleys: I β̇ β̈); dV_e/dt = (EA/l_f0) e1 ė1."""
    k = belt_kernel(model)
    el = model.elements[1]
    lf0 = math.sqrt(el.l0**2 - (R2 - R1) ** 2)
    elastic = bool(el.estiff)
    i1, i2 = res.coordinate_index(2, 1), res.coordinate_index(4, 1)
    p_in, dE = [], []
    for i in range(len(res.t)):
        x, v, a = res.x[i], res.xd[i], res.xdd[i]

        def T_along(s):
            return k.kinetic_energy(x + s * v, v + s * a)

        h = 1e-3 / max(np.abs(v).max(), np.abs(a).max())
        d = [(T_along(hh) - T_along(-hh)) / (2 * hh) for hh in (h, h / 2, h / 4)]
        d = [(4 * d[1] - d[0]) / 3, (4 * d[2] - d[1]) / 3]
        dT = (16 * d[1] - d[0]) / 15 + I1 * v[i1] * a[i1] + I2 * v[i2] * a[i2]
        dV = (EA / lf0) * res.e[i, 0] * res.ed[i, 0] if elastic else 0.0
        p_in.append(res.reaction[i, i1] * v[i1] + LOAD * v[i2])
        dE.append(dT + dV)
    return np.array(p_in), np.array(dE)


@pytest.mark.parametrize("rigid", [True, False], ids=["rigid", "elastic"])
def test_belt_drive_power_balance(rigid):
    """§6: the driving power r·β̇1 (reaction of the input coordinate) plus the load's power equals
    d/dt of the kinetic energy (pulleys and belt) plus the belt's strain energy, at every
    output time. The elastic belt oscillates (tension and speed ratio vary)."""
    model = belt_drive(rigid)
    res = model.run()
    p, dE = power_balance(model, res)
    assert np.max(np.abs(p - dE)) < 1e-10 * np.max(np.abs(p))
    if not rigid:
        w1, w2 = res.xd[:, res.coordinate_index(2, 1)], res.xd[:, res.coordinate_index(4, 1)]
        assert np.ptp(w2 / w1) > 1e-3  # the elastic belt really stretches and oscillates
        assert np.ptp(res.deformation(1, 1)) > 1e-5


def test_belt_drive_energy_over_the_run():
    """The integral of the power balance: E(t) − E(0) = ∫ (driving + load power) dt (Simpson on
    1600 intervals), with the belt's kinetic and strain energy."""
    model = belt_drive(rigid=False, n=1600, T=0.5)
    res = model.run()
    k = belt_kernel(model)
    el = model.elements[1]
    lf0 = math.sqrt(el.l0**2 - (R2 - R1) ** 2)
    i1, i2 = res.coordinate_index(2, 1), res.coordinate_index(4, 1)
    T = np.array([k.kinetic_energy(res.x[i], res.xd[i]) for i in range(len(res.t))])
    E = T + 0.5 * I1 * res.xd[:, i1] ** 2 + 0.5 * I2 * res.xd[:, i2] ** 2 + 0.5 * EA / lf0 * res.e[:, 0] ** 2
    P = res.reaction[:, i1] * res.xd[:, i1] + LOAD * res.xd[:, i2]
    W = cumulative_simpson(P, x=res.t, initial=0.0)
    assert np.max(np.abs(E - E[0] - W)) < 1e-8 * np.max(np.abs(W))


# ---------------------------------------------------------------------------------------------
# Rolling disc in steady circular motion
# ---------------------------------------------------------------------------------------------
#
# Steady motion of a thin disc (mass m, radius r, I_a = ½mr² about the axle, I_d = ¼mr² about a
# diameter) rolling without slip on the plane z = 0, gravity −g z (classical: Routh, Advanced
# Rigid Dynamics §244; O'Reilly, Nonlinear Dyn. 10 (1996) 287). Let t be the horizontal heading,
# n_h = z × t, the axle a = cos φ n_h + sin φ z (lean φ: for φ > 0 the top leans to −n_h) and
# d = cos φ z − sin φ n_h the in-plane direction from the contact point to the centre. In
# steady motion the disc turns at Ω about the vertical with constant lean and spin ω_s relative
# to the turning frame: ω = Ω z + ω_s a = ω_a a + Ω cos φ d with ω_a = ω_s + Ω sin φ. Rolling,
# v_G = ω × r d = r ω_a t, so the centre runs on a circle of signed radius ρ (centre at
# G + ρ n_h) with r ω_a = Ω ρ. Newton: contact force F = m Ω² ρ n_h + m g z. Euler about G with
# H = I_a ω_a a + I_d Ω cos φ d turning at Ω z: dH/dt = Ω cos φ (I_d Ω sin φ − I_a ω_a) t must
# equal −r d × F = m r (Ω² ρ cos φ + g sin φ) t, hence
#
#     Ω² [ I_d sin φ cos φ − (I_a + m r²) (ρ/r) cos φ ] = m g r sin φ.
#
# For r ≪ ρ this is the textbook tan φ = −(3/2) v²/(g ρ). Given φ and ρ it gives Ω, then
# ω_a = Ω ρ / r and ω_s = ω_a − Ω sin φ.

def disc_steady_state(phi, rho, m=1.0, r=0.1, g=9.81):
    Ia, Id = 0.5 * m * r * r, 0.25 * m * r * r
    k = Id * math.sin(phi) * math.cos(phi) - (Ia + m * r * r) * rho / r * math.cos(phi)
    Om2 = m * g * r * math.sin(phi) / k
    assert Om2 > 0, "no steady motion with this lean and radius"
    Om = math.copysign(math.sqrt(Om2), rho)  # forward speed v = Ω ρ > 0 (along +t)
    wa = Om * rho / r
    return Om, wa - Om * math.sin(phi)


def rolling_disc(phi, Om, ws, m=1.0, r=0.1, g=9.81, T=1.0, n=10, surface=(), centre=None):
    """BEARING 1 from the ground (10, 11) to the disc centre 1 and a turning frame 3 (vertical
    axis: e1 height RLSE, e2 = x and e3 = y kinematic coordinates of the slips, e4 = yaw and
    e5 = sin(lean) DOFs, e6 = pitch of the frame fixed at 0); HINGE 2 from the frame to the disc
    2 about the axle (e1 = spin DOF); WHEEL 3 (e1 fixed: contact, e2 and e3 ENHC) on the plane
    z = 0 or on the quadratic `surface` c1..c10, the centre starting at (0, 0, r) or `centre`."""
    M = spacar.Model()
    M.bearing(1, 10, 11, 1, 3, 0.0, 0.0, 1.0)
    M.hinge(2, 3, 2, 0.0, 1.0, 0.0)
    M.wheel(3, 1, 2, 0.0, 1.0, 0.0, r, *surface)
    M.xyz(10, 0.0, 0.0, 0.0)
    M.xyz(1, *(centre if centre is not None else (0.0, 0.0, r)))
    M.fix(10)
    M.fix(11)
    M.rlse(1, 1)
    M.dyne(1, 4, 5)
    M.dyne(2, 1)
    M.enhc(3, 2, 1, 2)
    M.enhc(3, 3, 1, 3)
    M.e(1, 5, math.sin(phi))
    M.ed(1, 4, Om)
    M.ed(2, 1, ws)
    M.mass(1, m)
    M.mass(2, 0.25 * m * r * r, 0, 0, 0.5 * m * r * r, 0, 0.25 * m * r * r)
    M.gravity(0.0, 0.0, -g)
    M.timestep(n, T)
    return tight(M)


def disc_drift(phi, rho, Om, ws, revolutions=5, r=0.1):
    res = rolling_disc(phi, Om, ws, T=revolutions * 2 * math.pi / abs(Om), n=40 * revolutions).run()
    x, y, z = res.node(1).x.T
    return (np.max(np.abs(res.deformation(1, 5) - math.sin(phi))),
            np.max(np.abs(np.hypot(x, y - rho) - abs(rho))),
            np.max(np.abs(z - r * math.cos(phi))),
            res)


@pytest.mark.parametrize("phi, rho", [(0.3, -1.0), (-0.5, 0.6), (0.1, -3.0)])
def test_rolling_disc_steady_circular_motion(phi, rho):
    """Exact steady-motion initial conditions (lean φ, turning rate Ω, spin ω_s for the centre
    circle of radius ρ): over five revolutions the lean stays constant, the centre stays on the
    predicted circle (centre (0, ρ), the disc starting at the origin heading +x) and at height
    r cos φ, the yaw rate stays Ω, and the kinematic coordinates x, y follow the circle."""
    Om, ws = disc_steady_state(phi, rho)
    d_lean, d_radius, d_height, res = disc_drift(phi, rho, Om, ws)
    assert d_lean < 1e-10
    assert d_radius < 1e-10 * abs(rho)
    assert d_height < 1e-12
    np.testing.assert_allclose(res.node(1).xd[0], [Om * rho, 0.0, 0.0], atol=1e-12)  # forward along +x
    np.testing.assert_allclose(res.element(1).ed[:, 3], Om, rtol=1e-9)
    np.testing.assert_allclose(res.element(2).ed[:, 0], ws, rtol=1e-9)
    np.testing.assert_allclose(res.deformation(1, 2), res.node(1).x[:, 0], atol=1e-12)
    # the heading turns at Ω: e4 = Ω t (yaw, continuous over the revolutions)
    np.testing.assert_allclose(res.deformation(1, 4), Om * res.t, rtol=1e-10, atol=1e-10)


def test_rolling_disc_drifts_when_the_condition_is_violated():
    """The check is sharp: a turning rate 1e-6 off the steady value makes the lean and radius
    drift by more than 1e-8 within five revolutions."""
    phi, rho = 0.3, -1.0
    Om, ws = disc_steady_state(phi, rho)
    d_lean, d_radius, _, _ = disc_drift(phi, rho, Om * (1 + 1e-6), ws)
    assert d_lean > 1e-8 and d_radius > 1e-8


# ---------------------------------------------------------------------------------------------
# Disc rolling in a spherical bowl (WHEEL on a quadratic surface)
# ---------------------------------------------------------------------------------------------

def bowl_disc(theta0, lean=0.0, yaw_rate=0.0, spin=0.0, Rb=1.0, r=0.1, T=3.0, n=60):
    """The rolling disc above in a spherical bowl of radius Rb, f = Rb² − |y − c|² with
    c = (0, 0, Rb) (c1..c3 = −1, c9 = 2 Rb), the centre started on the circle of radius Rb − r
    at angle θ0 from the bottom in the xz-plane, axle along y."""
    centre = ((Rb - r) * math.sin(theta0), 0.0, Rb - (Rb - r) * math.cos(theta0))
    return rolling_disc(lean, yaw_rate, spin, r=r, T=T, n=n, surface=(-1, -1, -1, 0, 0, 0, 0, 0, 2 * Rb, 0),
                        centre=centre)


def test_disc_rolling_in_a_bowl_is_a_pendulum():
    """Released from rest at θ0 = 0.5 rad in the vertical plane through the bowl's centre, the
    centre moves on the circle of radius Rb − r and θ(t) follows (Rb − r)(3/2) θ̈ = −g sin θ
    (I_a = m r²/2), integrated here by SciPy at rtol 1e-13."""
    Rb, r, g, theta0 = 1.0, 0.1, 9.81, 0.5
    res = bowl_disc(theta0).run()
    x, y, z = res.node(1).x.T
    theta = np.arctan2(x, Rb - z)
    ref = solve_ivp(lambda t, s: [s[1], -g * math.sin(s[0]) / (1.5 * (Rb - r))], (0.0, res.t[-1]),
                    [theta0, 0.0], method="DOP853", rtol=1e-13, atol=1e-14, t_eval=res.t)
    assert np.abs(theta - ref.y[0]).max() < 1e-9
    assert np.abs(np.hypot(x, Rb - z) - (Rb - r)).max() < 1e-12
    assert np.abs(y).max() < 1e-12 and np.abs(res.deformation(1, 5)).max() < 1e-12
    assert theta.min() < -0.49  # it swung through to the other side


def test_disc_rolling_in_a_bowl_in_3d_conserves_energy_without_slip():
    """Leaning, turning and spinning: T + V constant (the rolling constraints do no work) and the
    material point of the rim at the contact at rest, to the integration tolerance."""
    m, r, g, Rb = 1.0, 0.1, 9.81, 1.0
    J = np.diag([0.25 * m * r * r, 0.5 * m * r * r, 0.25 * m * r * r])
    res = bowl_disc(0.4, lean=0.2, yaw_rate=1.5, spin=-25.0, T=2.0, n=100).run()
    lam, lamd = res.node(2).x, res.node(2).xd
    w_body = body_angular_velocity(lam, lamd)
    T = 0.5 * m * (res.node(1).xd ** 2).sum(axis=1) + 0.5 * np.einsum("ti,ij,tj->t", w_body, J, w_body)
    E = T + m * g * res.node(1).x[:, 2]
    assert np.abs(E - E[0]).max() < 1e-9 * E[0]
    assert np.ptp(res.deformation(1, 4)) > 0.5 and np.ptp(res.deformation(1, 5)) > 0.05  # a 3-D motion
    # contact point: the rim point farthest from the bowl's centre c; its velocity ẋ + ω × (y − x)
    c = np.array([0.0, 0.0, Rb])
    for k in range(0, len(res.t), 10):
        R = R_(lam[k])
        a = R @ np.array([0.0, 1.0, 0.0])
        p = res.node(1).x[k]
        d = (p - c) - ((p - c) @ a) * a
        y = p + r * d / np.linalg.norm(d)
        assert abs(np.linalg.norm(y - c) - Rb) < 1e-10
        omega = R @ w_body[k]
        vc = res.node(1).xd[k] + np.cross(omega, y - p)
        assert np.linalg.norm(vc) < 1e-9


# ---------------------------------------------------------------------------------------------
# Whipple bicycle (Meijaard, Papadopoulos, Ruina & Schwab 2007)
# ---------------------------------------------------------------------------------------------

M_PUB = np.array([[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]])
C1_PUB = np.array([[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]])
K0_PUB = np.array([[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]])
K2_PUB = np.array([[0.0, 76.59734589573222], [0.0, 2.65431523794604]])
G, RR = 9.81, 0.3
WEAVE, CAPSIZE = 4.2923825363, 6.0242620153
LEAN_STEER = [0, 1]  # z = (lean e(1,5), steer e(4,1), rear-wheel rotation e(7,1))


def bicycle_text(v):
    text = BICYCLE.read_text()
    line = "ED        7   1  -16.666666666666667"
    assert line in text
    return text.replace(line, f"ED 7 1 {-float(v) / RR!r}")


def bicycle(v):
    """spacar's linearization of examples/bicycle.dat at forward speed v (rear-wheel spin −v/r_R)."""
    return spacar.linearize(spacar.read_string(bicycle_text(v)))


def lean_steer(lin):
    i = np.ix_(LEAN_STEER, LEAN_STEER)
    return lin.M0[i], lin.damping[i], lin.stiffness[i]


def published_eigenvalues(v):
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(M_PUB, G * K0_PUB + v * v * K2_PUB), -np.linalg.solve(M_PUB, v * C1_PUB)]])
    return np.linalg.eigvals(A)


def relerr(a, b):
    return float(np.max(np.abs(np.asarray(a) - b)) / np.max(np.abs(b)))


@pytest.fixture(scope="module")
def bicycle_matrices():
    """M, C1, K0, K2 from spacar's linearizations: M = M0, C1 = (C0 + D0)/v, g K0 = K(0),
    K2 = (K(v) − K(0))/v², at v = 0, 2, 5, 10 m/s (each must give the same)."""
    blocks = {v: lean_steer(bicycle(v)) for v in (0.0, 2.0, 5.0, 10.0)}
    K_at_0 = blocks[0.0][2]
    out = {"M": [b[0] for b in blocks.values()], "K0": K_at_0 / G,
           "C1": [blocks[v][1] / v for v in (2.0, 5.0, 10.0)],
           "K2": [(blocks[v][2] - K_at_0) / v**2 for v in (2.0, 5.0, 10.0)],
           "C_at_0": blocks[0.0][1]}
    return out


def test_bicycle_matrices_match_the_benchmark(bicycle_matrices):
    """The (lean, steer) blocks: M0 = M, C0 + D0 = v C1, K0 + N0 + G0 = g K0 + v² K2 to 1e-10
    relative (measured ~1e-14), with the benchmark's signs (lean to the right, steer to the
    right in its axes)."""
    b = bicycle_matrices
    for M in b["M"]:
        assert relerr(M, M_PUB) < 1e-10
    for C1 in b["C1"]:
        assert relerr(C1, C1_PUB) < 1e-10
    for K2 in b["K2"]:
        assert relerr(K2, K2_PUB) < 1e-10
    assert relerr(b["K0"], K0_PUB) < 1e-10
    assert np.max(np.abs(b["C_at_0"])) < 1e-10


def test_bicycle_full_linearization_structure():
    """The remaining coordinates decouple as §7.3 says: the rear-wheel rotation (z3) has no
    stiffness or damping coupling to lean and steer, and the kinematic coordinates x, y, yaw
    and the front-wheel rotation do not appear in R (K_k = 0), so their eigenvalues are zero."""
    lin = bicycle(5.0)
    assert [lbl[1:] for lbl in lin.z_labels] == [(1, 5), (4, 1), (7, 1)]
    assert [lbl[1:] for lbl in lin.y_labels] == [(1, 2), (1, 3), (1, 4), (8, 1)]
    scale = np.max(np.abs(lin.stiffness))
    assert np.max(np.abs(lin.Kk)) < 1e-12 * scale
    assert np.max(np.abs(lin.stiffness[2])) < 1e-12 * scale and np.max(np.abs(lin.stiffness[:, 2])) < 1e-12 * scale
    assert np.max(np.abs(lin.damping[2])) < 1e-12 and np.max(np.abs(lin.damping[:, 2])) < 1e-12
    assert lin.M0[0, 2] == 0.0 and lin.M0[1, 2] == 0.0
    # forward speed: ẋ = v along the rear wheel's rate, front-wheel rate (r_R/r_F) of it
    np.testing.assert_allclose(lin.AK0[0], [0, 0, -RR], atol=1e-14)
    np.testing.assert_allclose(lin.AK0[3], [0, 0, RR / 0.35], atol=1e-14)


@pytest.mark.parametrize("v", np.arange(0.0, 10.001, 0.5))
def test_bicycle_eigenvalues_match_the_benchmark(v):
    """Eigenvalues of spacar's full state matrix (§7.3; 10 states) against those of the published
    matrices at v = 0, 0.5, …, 10 m/s: every benchmark eigenvalue within 1e-10·max(1, |λ|)
    (measured < 2e-12); the six others are the zero eigenvalues of the kinematic coordinates and
    of the cyclic rear-wheel rotation (±√(round-off stiffness / mass) ≲ 1e-6)."""
    lam = bicycle(v).eigenvalues()
    assert lam.size == 10
    used = np.zeros(lam.size, bool)
    for z in published_eigenvalues(v):
        d = np.abs(lam - z)
        d[used] = np.inf
        j = int(np.argmin(d))
        used[j] = True
        assert d[j] < 1e-10 * max(1.0, abs(z)), (v, z, lam[j])
    assert np.max(np.abs(lam[~used])) < 1e-5


def lean_steer_eigenvalues(v):
    """Eigenvalues of the lean/steer part of spacar's linearization at speed v. By the block
    structure checked above (rear-wheel rotation decoupled, K_k = 0) these are exactly the
    non-trivial eigenvalues of the full state matrix; the trivial zeros are left out so that
    the capsize eigenvalue, which crosses zero, is not confused with them (at the crossing the
    full matrix has a defective zero eigenvalue: yaw grows linearly)."""
    M, C, K = lean_steer(bicycle(v))
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.linalg.eigvals(A)


def weave_real_part(v):
    lam = lean_steer_eigenvalues(v)
    return lam[np.abs(lam.imag) > 1e-6].real.max()


def capsize_eigenvalue(v):
    lam = lean_steer_eigenvalues(v)
    real = lam[lam.imag == 0].real
    return real[np.argmin(np.abs(real))]


def test_bicycle_weave_and_capsize_speeds():
    """Root finding on spacar's own linearization as a function of v: the weave eigenvalues'
    real part and the capsize eigenvalue cross zero at 4.2923825363 and 6.0242620153 m/s
    (benchmark, to 1e-8; measured 4e-11 and 9e-11 from the published, truncated, digits)."""
    v_weave = brentq(weave_real_part, 4.0, 5.0, xtol=1e-13, rtol=4 * np.finfo(float).eps)
    v_capsize = brentq(capsize_eigenvalue, 5.5, 6.5, xtol=1e-13, rtol=4 * np.finfo(float).eps)
    assert abs(v_weave - WEAVE) < 1e-8
    assert abs(v_capsize - CAPSIZE) < 1e-8
    # stable between them: the benchmark's self-stable speed range
    for v in (4.5, 5.0, 6.0):
        assert np.max(bicycle(v).eigenvalues().real) < 1e-5


def test_bicycle_eigenvalues_at_5_mps_published_digits():
    """The published values at v = 5 m/s: −14.0783897, −0.7753419 ± 4.4648677i, −0.3228664."""
    lam = lean_steer_eigenvalues(5.0)
    expected = [-14.0783897, -0.7753419 + 4.4648677j, -0.7753419 - 4.4648677j, -0.3228664]
    for z in expected:
        assert np.min(np.abs(lam - z)) < 1e-7


# ---------------------------------------------------------------------------------------------
# Planar cart
# ---------------------------------------------------------------------------------------------

WHEELBASE, STEER, R_WHEEL = 1.2, 0.35, 0.3


def cart_frame(M, masses):
    """The cart of both cart models: PLBEAR 1 from the ground (1, 2) to the body (rear-axle
    centre 3, heading 4); PLBEAR 2 welds the front wheel (centre 5, heading 6) to the body,
    WHEELBASE ahead and steered by STEER (E 2 3); PLWHEELs 3 (rear: 3, 4, spin 7) and 4
    (front: 5, 6, spin 8); PLHINGE 5 from the ground orientation 2 to the front spin 8: its e1
    is the front wheel's spin angle, a deformation that can be a kinematic coordinate."""
    M.plbear(1, 1, 2, 3, 4)
    M.plbear(2, 3, 4, 5, 6)
    M.plwheel(3, 3, 4, 7, R_WHEEL, 0.0, 1.0)
    M.plwheel(4, 5, 6, 8, R_WHEEL, 0.0, 1.0)
    M.plhinge(5, 2, 8)
    M.xy(1, 0.5, -0.2)
    M.xy(3, 0.5, -0.2)
    M.xy(5, 0.5 + WHEELBASE, -0.2)
    M.fix(1)
    M.fix(2)
    M.e(2, 3, STEER)
    for node, value in masses.items():
        M.mass(node, value)
    return M


def rolling_cart(masses=None, spin_rate=10.0, T=8.0, n=80, gravity=None):
    """Both wheels rolling without slip: rear slips ↔ x, y (PLBEAR 1 e1, e2), front lateral slip ↔
    heading (e3), front longitudinal slip ↔ the front spin hinge; rear spin 7 DYNX."""
    masses = masses or {3: 10.0, 4: 1.5, 5: 3.0, 6: 0.2, 7: 0.1, 8: 0.1}
    M = cart_frame(spacar.Model(), masses)
    M.dynx(7)
    M.xd(7, 1, spin_rate)
    M.enhc(3, 1, 1, 1)
    M.enhc(3, 2, 1, 2)
    M.enhc(4, 2, 1, 3)
    M.enhc(4, 1, 5, 1)
    if gravity is not None:
        M.gravity(*gravity)
    M.timestep(n, T)
    return tight(M)


def test_cart_turning_radius():
    """Constant steer δ, wheelbase L: the rear axle centre runs on a circle of radius L/tan δ,
    the front wheel on L/sin δ, about the same centre; heading rate v tan δ / L; speed constant
    (the constraint forces do no work)."""
    res = rolling_cart().run()
    R = WHEELBASE / math.tan(STEER)
    centre = np.array([0.5, -0.2 + R])  # to the left of the initial heading +x
    rear, front = res.node(3).x, res.node(5).x
    assert np.max(np.abs(np.linalg.norm(rear - centre, axis=1) - R)) < 1e-10 * R
    assert np.max(np.abs(np.linalg.norm(front - centre, axis=1) - WHEELBASE / math.sin(STEER))) < 1e-10 * R
    v = R_WHEEL * 10.0
    np.testing.assert_allclose(np.linalg.norm(res.node(3).xd, axis=1), v, rtol=1e-12)
    np.testing.assert_allclose(res.node(4).xd[:, 0], v * math.tan(STEER) / WHEELBASE, rtol=1e-12)
    assert res.node(4).x[-1, 0] > 2 * math.pi  # more than one full turn


def creep_cart(T=2.0, n=400):
    """Lateral slips released with creep damping (EDAMPP 0 d), longitudinal slips rolling: the
    body position and heading (PLBEAR 1 e1..e3) are DOFs, the wheel spins are kinematic
    coordinates of the longitudinal slips through PLHINGE 5 (front) and 6 (rear, from the
    ground orientation 2 to the spin 7). (With x as the kinematic coordinate of the rear
    longitudinal slip instead, the velocity block is singular whenever the cart heads along y.)"""
    M = cart_frame(spacar.Model(), {3: 10.0, 4: 1.5, 5: 3.0, 6: 0.2, 7: 0.1, 8: 0.1})
    M.plhinge(6, 2, 7)
    M.dyne(1)
    M.ed(1, 1, 3.0)
    M.ed(1, 2, 0.5)
    M.ed(1, 3, 0.8)
    M.enhc(3, 1, 6, 1)
    M.enhc(4, 1, 5, 1)
    M.rlse(3, 2)
    M.rlse(4, 2)
    M.edampp(3, 0.0, 40.0)
    M.edampp(4, 0.0, 25.0)
    M.timestep(n, T)
    return tight(M)


CART_MASSES = {(3, 1): 10.0, (3, 2): 10.0, (4, 1): 1.5, (5, 1): 3.0, (5, 2): 3.0, (6, 1): 0.2,
               (7, 1): 0.1, (8, 1): 0.1}


def test_creep_dissipation_equals_creep_power():
    """Released lateral slips with σ = d ė: the kinetic energy decreases at the creep power
    Σ d ė² — at every output time (dE/dt = Σ m ẋ ẍ from the outputs) and over the run
    (E(0) − E(t) = ∫ Σ d ė² dt, Simpson). The slips' values are their integrated rates."""
    res = creep_cart().run()
    idx = {k: res.coordinate_index(*k) for k in CART_MASSES}
    E = sum(0.5 * m * res.xd[:, idx[k]] ** 2 for k, m in CART_MASSES.items())
    dE = sum(m * res.xd[:, idx[k]] * res.xdd[:, idx[k]] for k, m in CART_MASSES.items())
    rear, front = res.deformation_index(3, 2), res.deformation_index(4, 2)
    P = 40.0 * res.ed[:, rear] ** 2 + 25.0 * res.ed[:, front] ** 2
    np.testing.assert_allclose(res.sigma[:, rear], 40.0 * res.ed[:, rear], rtol=1e-14, atol=1e-14)
    assert np.max(np.abs(dE + P)) < 1e-12 * np.max(P)
    W = cumulative_simpson(P, x=res.t, initial=0.0)
    assert W[-1] > 0.3 * E[0]  # a large part of the energy is dissipated
    assert np.max(np.abs(E[0] - E - W)) < 1e-6 * W[-1]
    slip = cumulative_simpson(res.ed[:, rear], x=res.t, initial=0.0)
    assert np.max(np.abs(res.deformation(3, 2) - slip)) < 1e-6


# ---------------------------------------------------------------------------------------------
# Linearization: kinematic coordinates that do not appear in R
# ---------------------------------------------------------------------------------------------

def test_cart_linearization_zero_eigenvalues():
    """On a level plane nothing in R depends on x, y, heading or the front spin (K_k = 0) and
    the rear spin is cyclic: the state (θ, x, y, ψ, θ_f, θ̇) has only zero eigenvalues. The
    rates of the kinematic coordinates still depend on the motion (AK0): ẋ = r θ̇, ψ̇ = r θ̇ tan δ/L,
    front spin θ̇_f = θ̇ / cos δ (the front wheel runs on the larger circle)."""
    lin = spacar.linearize(rolling_cart())
    assert [lbl[1:] for lbl in lin.z_labels] == [(7, 1)]
    assert [lbl[1:] for lbl in lin.y_labels] == [(1, 1), (1, 2), (1, 3), (5, 1)]
    assert np.max(np.abs(lin.Kk)) < 1e-10
    np.testing.assert_allclose(lin.AK0[:, 0], [R_WHEEL, 0.0, R_WHEEL * math.tan(STEER) / WHEELBASE,
                                               1.0 / math.cos(STEER)], atol=1e-12)
    lam = lin.eigenvalues()
    assert lam.size == 6 and np.max(np.abs(lam)) < 1e-6


@pytest.mark.parametrize("heading", [0.7, -0.9])
def test_cart_on_incline_linearization(heading):
    """On an incline (in-plane gravity G along x) the heading enters R: with a point mass m on
    the rear axle and rear-spin inertia I only, μ θ̈ = m G r cos ψ (μ = m r² + I) and
    ψ̇ = κ r θ̇ (κ = tan δ / L), so K_k = ∂R/∂ψ = m G r sin ψ and the (ψ, θ̇) pair has
    λ² = −κ r² m G sin ψ / μ; x, y, the front spin and θ do not appear in R: four zero
    eigenvalues."""
    m, I, Gx = 8.0, 0.3, 2.5
    model = rolling_cart(masses={3: m, 7: I}, spin_rate=4.0, gravity=(Gx, 0.0))
    model.e(1, 3, heading)
    lin = spacar.linearize(model)
    r, kappa, mu = R_WHEEL, math.tan(STEER) / WHEELBASE, m * R_WHEEL**2 + I
    np.testing.assert_allclose(lin.M0, [[mu]], rtol=1e-13)
    np.testing.assert_allclose(lin.Kk[0], [0.0, 0.0, m * Gx * r * math.sin(heading), 0.0], atol=1e-9)
    lam = lin.eigenvalues()
    lam2 = -kappa * r * r * m * Gx * math.sin(heading) / mu
    nontrivial = np.sqrt(complex(lam2)) * np.array([1, -1])
    zero = np.abs(lam) < 1e-6
    assert zero.sum() == 4
    for z in nontrivial:
        assert np.min(np.abs(lam[~zero] - z)) < 1e-9 * abs(z)


# ---------------------------------------------------------------------------------------------
# ENHC errors
# ---------------------------------------------------------------------------------------------

def wheel_on_plane():
    M = spacar.Model()
    M.plbear(1, 1, 2, 3, 4)
    M.plwheel(2, 3, 4, 5, 0.4, 0.0, 1.0)
    M.fix(1)
    M.fix(2)
    M.dynx(5)
    M.mass(3, 1.0)
    M.mass(5, 0.1)
    return M


def test_enhc_kinematic_coordinate_must_be_fixed():
    """Manual §5.3 note 2: the kinematic coordinate must otherwise be a fixed deformation."""
    M = wheel_on_plane()
    M.rlse(1, 1)
    with pytest.raises(spacar.InputError, match=r"element 1 deformation 1 must be a fixed deformation, it is released"):
        M.enhc(2, 1, 1, 1)
    M = wheel_on_plane()
    M.dyne(1, 2)
    with pytest.raises(spacar.InputError, match=r"must be a fixed deformation, it is dynamic"):
        M.enhc(2, 2, 1, 2)


def test_enhc_kinematic_coordinate_cannot_be_reclassified_or_shared():
    M = wheel_on_plane()
    M.enhc(2, 1, 1, 1)
    with pytest.raises(spacar.InputError, match=r"kinematic coordinate of a nonholonomic deformation"):
        M.rlse(1, 1)
    with pytest.raises(spacar.InputError, match=r"already the kinematic coordinate of element 2 deformation 1"):
        M.enhc(2, 2, 1, 1)
    with pytest.raises(spacar.InputError, match=r"cannot be its own kinematic coordinate"):
        M.enhc(2, 2, 2, 2)


@pytest.mark.parametrize("declare, cls", [(lambda M: None, "fixed"), (lambda M: M.dyne(2, 2), "dynamic"),
                                          (lambda M: M.inpute(2, 2), "input")])
def test_velocity_level_deformation_must_be_enhc_or_released(declare, cls):
    """A slip is defined by its rate only: fixed (the default), dynamic or input is an error that
    names the deformation."""
    M = wheel_on_plane()
    M.enhc(2, 1, 1, 1)
    declare(M)
    with pytest.raises(spacar.InputError, match=rf"element 2 \(PLWHEEL\) deformation 2 is defined by its rate only "
                                                rf"\(velocity level\).*not {cls}"):
        M.run()


def test_velocity_level_deformation_cannot_be_a_kinematic_coordinate():
    M = wheel_on_plane()
    M.enhc(2, 1, 2, 2)
    with pytest.raises(spacar.InputError, match=r"element 2 \(PLWHEEL\) deformation 2 is defined by its rate only"):
        M.run()


def test_badly_chosen_kinematic_coordinate_is_diagnosed_at_velocity_level():
    """Pairing the lateral slip with the heading (which the slip rate does not contain) leaves the
    velocity block singular; the diagnosis analyses that block and names the rows involved."""
    M = wheel_on_plane()
    M.enhc(2, 1, 1, 1)
    M.enhc(2, 2, 1, 3)
    with pytest.raises(spacar.KinematicsError) as err:
        M.run()
    text = str(err.value)
    assert "velocity constraint block is singular" in text
    assert "velocity constraint equations" in text and "rank 2" in text
    assert "pair each nonholonomic" in text
    assert "element 2 (PLWHEEL) deformation 2" in text


# ---------------------------------------------------------------------------------------------
# Dump and restart
# ---------------------------------------------------------------------------------------------

def restart_matches(make, t_half):
    """Run 2·t_half; run t_half, dump with 17 digits, read the dump and run t_half: the states at
    the end agree."""
    whole = make(2 * t_half, 2)
    r2 = whole.run()
    first = make(t_half, 1)
    first.run()
    text = first.dump(digits=17)
    again = spacar.read_string(text, "dump.dat")
    r1 = again.run()
    assert r1.t[-1] == pytest.approx(2 * t_half, abs=1e-15)
    return text, r1, r2


def test_restart_of_the_bicycle():
    """Nonlinear run of the benchmark bicycle at 5 m/s with an initial lean rate: 1 s + dump +
    1 s equals a 2 s run (kinematic-coordinate E values, ENHC lines)."""
    def make(T, n):
        text = bicycle_text(5.0).replace("LINEAR    1\n", f"ED 1 5 0.5\nTIMESTEP {n} {T}\n")
        return tight(spacar.read_string(text), epsint=1e-11, epsind=1e-11)

    text, r1, r2 = restart_matches(make, 1.0)
    assert text.count("ENHC") == 4
    assert re.search(r"^E +1 +2 ", text, re.M) and re.search(r"^E +8 +1 ", text, re.M)
    assert np.max(np.abs(r1.x[-1] - r2.x[-1])) < 1e-10
    assert np.max(np.abs(r1.xd[-1] - r2.xd[-1])) < 1e-9
    assert np.max(np.abs(r1.e[-1] - r2.e[-1])) < 1e-10
    assert abs(r2.deformation(1, 2)[-1] - 9.88) < 0.01  # it did ride ~10 m


def test_restart_keeps_integrated_slips():
    """The released slips' values are integrated states: the dump carries them (E) and a restart
    continues them, as do the kinematic coordinates (the wheel spins here)."""
    def make(T, n):
        return creep_cart(T=T, n=n)

    text, r1, r2 = restart_matches(make, 1.0)
    assert re.search(r"^E +3 +2 ", text, re.M) and re.search(r"^E +4 +2 ", text, re.M)
    assert abs(r2.deformation(3, 2)[-1]) > 0.1
    assert np.max(np.abs(r1.x[-1] - r2.x[-1])) < 1e-10
    assert np.max(np.abs(r1.e[-1] - r2.e[-1])) < 1e-10


def test_next_block_continues_integrated_slips():
    """Within one model, a second block continues the slips' values."""
    m = creep_cart(T=1.0, n=2)
    r1 = m.run()
    r2 = m.run()
    assert r2.deformation(3, 2)[0] == r1.deformation(3, 2)[-1]
    whole = creep_cart(T=2.0, n=2).run()
    assert abs(r2.deformation(3, 2)[-1] - whole.deformation(3, 2)[-1]) < 1e-10


# ---------------------------------------------------------------------------------------------
# The command line
# ---------------------------------------------------------------------------------------------

def test_cli_prints_the_bicycle_eigenvalues():
    """`spacar run examples/bicycle.dat` prints the eigenvalues of the linearized equations as a
    comment (the benchmark's at 5 m/s to the 8 printed digits, and the count of zero ones)
    before the dump; the output is valid input and, read again, linearizes to the same
    eigenvalues (lossless dump, --dump-digits 17)."""
    proc = subprocess.run([sys.executable, "-m", "spacar", "run", "--dump-digits", "17", str(BICYCLE)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    line = next(l for l in proc.stdout.splitlines() if l.startswith("* eigenvalues"))
    assert "(6 zero)" in line
    values = np.array([complex(tok.replace("i", "j")) for tok in line.split(":", 1)[1].split()])
    expected = [-14.0783897, -0.32286643, -0.77534188 + 4.4648677j, -0.77534188 - 4.4648677j]
    assert len(values) == 4
    for z in expected:
        assert np.min(np.abs(values - z)) < 1e-7 * abs(z)
    again = spacar.read_string(proc.stdout, "bicycle-dump.dat")
    lam = spacar.linearize(again).eigenvalues()
    for z in published_eigenvalues(5.0):
        assert np.min(np.abs(lam - z)) < 1e-9 * abs(z)
