"""Reaction forces and element stresses (FORCEMODE; issue #5, formulation.md §6).

* statics: a clamped cantilever (planar PLBEAM and spatial BEAM, rigid and flexible in its
  deflected equilibrium) under a tip force and moment: the reaction force and moment at the
  clamp balance the load to 1e-10; sign convention: r is the load exerted by the support on
  the node;
* driving forces: the rigid slider-crank driven by INPUTX (reaction on the crank angle) or by
  INPUTE (stress σ^p of a PLHINGE), and the manual's flexible slider-crank: power balance
  τ·ω = dE/dt with E computed independently;
* FORCEMODE 2: stresses of rigid deformations are constraint forces: joint forces of a rigid
  slider-crank and the pivot force of a rigid pendulum against a Newton–Euler calculation by
  hand;
* the consistency checks of §6: σ^d from (6.1) equals the constitutive σ^d and the rows of
  g + DDᵀσ of the degrees of freedom and of the calculable coordinates vanish.

References are computed here from rigid-body mechanics; from the core only the public results
and `spacar._core.Simulation` (evaluate/move_to, forces and the Data arrays) are used.
"""
from __future__ import annotations


import numpy as np
import pytest

import spacar
from support.equilibrium import static_equilibrium
from support.paths import EXAMPLES
from support.simulation import assembled

EXAMPLE = EXAMPLES / "slidercrank.dat"
G = 9.81


def euler_E(lam):
    l0, l1, l2, l3 = lam
    return np.array([[-l1, l0, -l3, l2], [-l2, l3, l0, -l1], [-l3, -l2, l1, l0]])


def cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


# --------------------------------------------------------------------------------------------
# Statics: clamped cantilevers
# --------------------------------------------------------------------------------------------

def planar_cantilever(n, force, torque, flexible, L=1.0, slope=0.0):
    """n PLBEAMs from the clamped node 1/2 to the tip node 2n+1/2n+2 along a line of slope
    `slope`; FORCE (fx, fy) and a torque on the tip. Flexible: bending DYNE (EI = 1, EA = 100)."""
    m = spacar.Model()
    for k in range(n):
        m.plbeam(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4)
        m.x(2 * k + 3, L * (k + 1) / n, slope * L * (k + 1) / n)
        m.emass(k + 1, 1.0)
        if flexible:
            m.estiff(k + 1, 100.0, 1.0)
            m.dyne(k + 1, 2, 3)
    m.fix(1)
    m.fix(2)
    m.force(2 * n + 1, *force)
    m.force(2 * n + 2, torque)
    m.forcemode(2)
    m.epskin(1e-12)
    return m


@pytest.mark.parametrize("slope", [0.0, 0.4])
def test_rigid_planar_cantilever_reaction_balances_tip_load(slope):
    """All deformations rigid: the kinematic analysis alone gives the reaction at the clamp,
    r = −F and moment −(x_tip − x_root) × F − T (the load of the support on the node)."""
    F, T = np.array([0.3, -2.0]), 0.5
    res = planar_cantilever(3, F, T, flexible=False, slope=slope).run()
    r = res.reaction[0]
    tip = res.node(7).x[0]
    moment = -cross2(tip, F) - T
    load = np.hypot(*F) + abs(T)
    assert abs(r[res.coordinate_index(1, 1)] + F[0]) <= 1e-10 * load
    assert abs(r[res.coordinate_index(1, 2)] + F[1]) <= 1e-10 * load
    assert abs(r[res.coordinate_index(2, 1)] - moment) <= 1e-10 * load
    # Only supports carry reactions.
    others = [i for i, (n, _) in enumerate(res.coordinate_labels) if n not in (1, 2)]
    assert np.all(res.reaction[:, others] == 0.0)
    # Sign: a downward tip load is carried by an upward support force.
    assert r[res.coordinate_index(1, 2)] > 0


def test_flexible_planar_cantilever_reaction_in_deflected_equilibrium():
    """Bending DYNE: at the static equilibrium (q̈ = 0) the reaction balances the load about
    the deflected tip, to 1e-10 of the load."""
    F, T = np.array([0.3, -2.0]), 0.5
    sim, q = static_equilibrium(planar_cantilever(4, F, T, flexible=True))
    sim.forces()
    r, x = np.array(sim.data.reaction), np.array(sim.data.x)
    labels = [tuple(lbl) for lbl in sim.system.coord_label]
    idx = {lbl: i for i, lbl in enumerate(labels)}
    tip = x[[idx[(9, 1)], idx[(9, 2)]]]
    assert np.abs(tip[1]) > 0.1  # clearly deflected: the moment arm differs from the undeformed one
    load = np.hypot(*F) + abs(T)
    assert abs(r[idx[(1, 1)]] + F[0]) <= 1e-10 * load
    assert abs(r[idx[(1, 2)]] + F[1]) <= 1e-10 * load
    assert abs(r[idx[(2, 1)]] + cross2(tip, F) + T) <= 1e-10 * load


def spatial_cantilever(n, force, moment):
    m = spacar.Model()
    for k in range(n):
        m.beam(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4, 0.0, 1.0, 0.0)
        m.x(2 * k + 3, (k + 1) / n, 0.2 * (k + 1) / n, -0.1 * (k + 1) / n)
    m.fix(1)
    m.fix(2)
    tip = 2 * n + 1
    m.force(tip, *force)
    # A global moment on a LAMBDA node is the λ-force 2 Eᵀ m (formulation.md §3.4).
    m.force(tip + 1, *(2 * euler_E((1, 0, 0, 0)).T @ moment))
    m.forcemode(2)
    return m


def test_rigid_spatial_cantilever_reaction_force_and_moment():
    F, Mt = np.array([0.3, -2.0, 0.7]), np.array([0.1, 0.2, -0.4])
    res = spatial_cantilever(3, F, Mt).run()
    r = res.reaction[0]
    force = r[[res.coordinate_index(1, i) for i in (1, 2, 3)]]
    tip = res.node(7).x[0]
    load = np.linalg.norm(F) + np.linalg.norm(Mt)
    assert np.abs(force + F).max() <= 1e-10 * load
    moment = res.reaction_moment(2)[0]
    assert np.abs(moment + np.cross(tip, F) + Mt).max() <= 1e-10 * load
    # Same moment by hand from the λ-reactions.
    lam = res.node(2).x[0]
    r_lam = r[[res.coordinate_index(2, i) for i in (1, 2, 3, 4)]]
    assert np.allclose(0.5 * euler_E(lam) @ r_lam, moment, rtol=0, atol=1e-14)
    with pytest.raises(spacar.InputError):
        res.reaction_moment(1)


# --------------------------------------------------------------------------------------------
# Driving forces: power balance of the slider-crank
# --------------------------------------------------------------------------------------------

CRANK, ROD = (0.15, 0.2225), (0.30, 0.4)   # (length, ρA) of the rigid links
M_SLIDER, I_CRANK, M_PIN = 0.5, 0.01, 0.02   # slider mass, BETA inertia on node 2, MASS on β5


def rigid_slider_crank(drive, omega=1.5, alpha=0.7, n_out=40, T=1.0):
    """Crank 1 (nodes 1, 2 → 3, 4), rod 2 (3, 5 → 6, 7), slider node 6 on y = 0, all
    deformations rigid, gravity; the crank turns with ω(t) = ω + α t, driven either by INPUTX on
    β2 or by INPUTE on a PLHINGE 3 between a fixed BETA node 10 and β2."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 5, 6, 7)
    m.x(3, CRANK[0], 0.0)
    m.x(6, CRANK[0] + ROD[0], 0.0)
    m.fix(1)
    m.fix(6, 2)
    m.emass(1, CRANK[1])
    m.emass(2, ROD[1])
    m.mass(6, M_SLIDER)
    m.mass(2, I_CRANK)
    m.mass(5, M_PIN)
    m.gravity(0.0, -G)
    if drive == "INPUTX":
        m.inputx(2, 1)
        m.xd(2, 1, omega)
        m.xdd(2, 1, alpha)
    else:
        m.plhinge(3, 10, 2)
        m.fix(10)
        m.inpute(3, 1)
        m.ed(3, 1, omega)
        m.edd(3, 1, alpha)
    m.forcemode(1)
    m.timestep(n_out, T)
    return m


def rigid_power(res):
    """dE/dt, E = T + V_g of the rigid links (exact rigid-bar energy: centre of mass and
    m l²/12), the slider and the rotational inertias, from x, ẋ, ẍ."""
    c = res.coordinate_index
    x, v, a = res.x, res.xd, res.xdd
    P = M_SLIDER * (v[:, c(6, 1)] * a[:, c(6, 1)] + v[:, c(6, 2)] * a[:, c(6, 2)] + G * v[:, c(6, 2)])
    P += I_CRANK * v[:, c(2, 1)] * a[:, c(2, 1)] + M_PIN * v[:, c(5, 1)] * a[:, c(5, 1)]
    for (p, q), (L, rho) in (((1, 3), CRANK), ((3, 6), ROD)):
        mass = rho * L
        vp, vq = v[:, [c(p, 1), c(p, 2)]], v[:, [c(q, 1), c(q, 2)]]
        ap, aq = a[:, [c(p, 1), c(p, 2)]], a[:, [c(q, 1), c(q, 2)]]
        P += mass * np.sum(0.25 * (vp + vq) * (ap + aq), axis=1)        # ½ m |v_c|²
        P += mass / 12 * np.sum((vq - vp) * (aq - ap), axis=1)          # ½ (m L²/12) ω²
        P += mass * G * 0.5 * (vp[:, 1] + vq[:, 1])                     # m g y_c
    return P


def rigid_energy(res):
    c = res.coordinate_index
    x, v = res.x, res.xd
    E = 0.5 * M_SLIDER * (v[:, c(6, 1)] ** 2 + v[:, c(6, 2)] ** 2) + M_SLIDER * G * x[:, c(6, 2)]
    E += 0.5 * I_CRANK * v[:, c(2, 1)] ** 2 + 0.5 * M_PIN * v[:, c(5, 1)] ** 2
    for (p, q), (L, rho) in (((1, 3), CRANK), ((3, 6), ROD)):
        mass = rho * L
        vp, vq = v[:, [c(p, 1), c(p, 2)]], v[:, [c(q, 1), c(q, 2)]]
        E += 0.5 * mass * np.sum((0.5 * (vp + vq)) ** 2, axis=1) + mass / 24 * np.sum((vq - vp) ** 2, axis=1)
        E += mass * G * 0.5 * (x[:, c(p, 2)] + x[:, c(q, 2)])
    return E


@pytest.mark.parametrize("drive", ["INPUTX", "INPUTE"])
def test_rigid_slider_crank_driving_torque_power_balance(drive):
    """τ·ω = dE/dt to 1e-6 (relative to the peak power) over a turn and a half of an
    accelerating crank: τ is the reaction on the input coordinate β2 (INPUTX) or −σ^p of the
    input hinge deformation (INPUTE: the hinge's load on the nodes is −DDᵀσ)."""
    res = rigid_slider_crank(drive, T=4.0, n_out=80).run()
    if drive == "INPUTX":
        j = res.coordinate_index(2, 1)
        power = res.reaction[:, j] * res.xd[:, j]
        assert np.all(res.sigma[:, res.deformation_index(1, 1)] != 0)  # FORCEMODE 1: stresses too
    else:
        k = res.deformation_index(3, 1)
        power = -res.sigma[:, k] * res.ed[:, k]
        # The driver of an input deformation acts through σ^p; the coordinates it drives
        # are not inputs and carry no reaction.
        assert np.all(res.reaction[:, res.coordinate_index(2, 1)] == 0.0)
    dE = rigid_power(res)
    scale = np.abs(power).max()
    assert scale > 0.1
    assert np.abs(power - dE).max() <= 1e-6 * scale
    # Independent of ẍ: the work equals the energy change (trapezoidal rule on a fine grid
    # with the end corrections of the Euler–Maclaurin formula, h⁴ accurate).
    fine = rigid_slider_crank(drive, T=1.0, n_out=400).run()
    if drive == "INPUTX":
        j = fine.coordinate_index(2, 1)
        p_fine = fine.reaction[:, j] * fine.xd[:, j]
    else:
        k = fine.deformation_index(3, 1)
        p_fine = -fine.sigma[:, k] * fine.ed[:, k]
    h = fine.t[1] - fine.t[0]
    dp0 = (-3 * p_fine[0] + 4 * p_fine[1] - p_fine[2]) / (2 * h)
    dp1 = (3 * p_fine[-1] - 4 * p_fine[-2] + p_fine[-3]) / (2 * h)
    work = h * (p_fine.sum() - 0.5 * (p_fine[0] + p_fine[-1])) - h * h / 12 * (dp1 - dp0)
    E = rigid_energy(fine)
    assert abs(work - (E[-1] - E[0])) <= 1e-6 * np.abs(p_fine).max() * (fine.t[-1] - fine.t[0])


def test_both_drives_give_the_same_torque():
    a = rigid_slider_crank("INPUTX").run()
    b = rigid_slider_crank("INPUTE").run()
    tau_x = a.reaction[:, a.coordinate_index(2, 1)]
    tau_e = -b.sigma[:, b.deformation_index(3, 1)]
    assert np.abs(tau_x - tau_e).max() <= 1e-12 * np.abs(tau_x).max()


def test_flexible_slider_crank_power_balance():
    """The manual's slider-crank (elastic rod, 4 DYNE): d/dt(T + V_e) = r_p ẋ^p along the
    integrated motion (formulation.md §6); T = ½ẋᵀMẋ with Ṁ by differences along the motion,
    V_e = ½eᵀSe from the ESTIFF values of the input."""
    text = EXAMPLE.read_text().replace("Timestep 100 5.0", "Timestep 4 1.0")
    model = spacar.read_string(text)
    model.epsint(1e-10)
    model.epsind(1e-10)
    copy = model.copy()
    res = model.run()
    sim = assembled(copy)
    s = sim.system
    EI, l0 = 0.0012723, 0.15
    S = EI / l0**3 * np.array([[4.0, -2.0], [-2.0, 4.0]])
    jb = res.coordinate_index(2, 1)
    for k in range(1, len(res.t)):
        t = res.t[k]
        q = np.concatenate([res.x[k, s.x_dyn], res.e[k, s.e_dyn]])
        qd = np.concatenate([res.xd[k, s.x_dyn], res.ed[k, s.e_dyn]])
        qdd = np.concatenate([res.xdd[k, s.x_dyn], res.edd[k, s.e_dyn]])

        def mass_at(dt):
            sim.evaluate(t + dt, q + qd * dt + 0.5 * qdd * dt * dt, qd + qdd * dt)
            return np.array(sim.data.M)

        h = 1e-4
        Mdot = (mass_at(-2 * h) - 8 * mass_at(-h) + 8 * mass_at(h) - mass_at(2 * h)) / (12 * h)
        sim.evaluate(t, q, qd)
        sim.forces()
        d = sim.data
        xd, xdd, M, e, ed = (np.array(a) for a in (d.xd, d.xdd, d.M, d.e, d.ed))
        dT = xd @ M @ xdd + 0.5 * xd @ Mdot @ xd
        dV = sum(e[[res.deformation_index(el, 2), res.deformation_index(el, 3)]] @ S
                 @ ed[[res.deformation_index(el, 2), res.deformation_index(el, 3)]] for el in (2, 3))
        power = np.array(d.reaction)[jb] * xd[jb]
        assert abs(power - res.reaction[k, jb] * res.xd[k, jb]) <= 1e-8 * abs(power)
        assert abs(dT + dV - power) <= 1e-6 * 5e-3  # peak power of the drive ≈ 5e-3 W


def test_forcemode_levels():
    """FORCEMODE 0: no reactions (and only constitutive stresses); 1 and 2: reactions on the
    fixed and input coordinates and the reaction stresses."""
    out = {}
    for mode in (0, 1, 2):
        m = rigid_slider_crank("INPUTX", n_out=4)
        m.forcemode(mode)
        out[mode] = m.run()
    assert np.all(out[0].reaction == 0.0) and np.all(out[0].sigma == 0.0)
    for mode in (1, 2):
        assert np.array_equal(out[mode].reaction, out[1].reaction)
        assert np.array_equal(out[mode].sigma, out[1].sigma)
    r = out[2]
    fixed_or_input = {(1, 1), (1, 2), (2, 1), (6, 2)}
    for i, lbl in enumerate(r.coordinate_labels):
        if lbl not in fixed_or_input:
            assert np.all(r.reaction[:, i] == 0.0), lbl
    assert np.all(np.abs(r.reaction[:, r.coordinate_index(6, 2)]) > 0)


# --------------------------------------------------------------------------------------------
# Constraint forces against Newton–Euler
# --------------------------------------------------------------------------------------------

def test_slider_crank_joint_forces_newton_euler():
    """Massless rigid crank and rod, a point mass at the crank pin A (node 3), the slider mass
    at B (node 6), a crank inertia on β2; all deformations rigid. By hand: the rod is a
    two-force member with tension N = σ1 of element 2; slider: m_B a_Bx = −N u_x, normal force
    R_B = N u_y + m_B g; crank pin: F = m_A (a_A − g) − N u; pivot reaction R_O = F; driving
    torque τ = I α + (x_A − x_O) × F."""
    mA, mB, I = 0.3, 0.5, 0.02
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 5, 6, 7)
    m.x(3, 0.15, 0.0)
    m.x(6, 0.45, 0.0)
    m.fix(1)
    m.fix(6, 2)
    m.mass(3, mA)
    m.mass(6, mB)
    m.mass(2, I)
    m.gravity(0.0, -G)
    m.inputx(2, 1)
    m.xd(2, 1, 2.0)
    m.xdd(2, 1, 1.5)
    m.forcemode(2)
    m.timestep(12, 3.0)
    res = m.run()
    g = np.array([0.0, -G])
    for k in range(len(res.t)):
        xA, xB = res.node(3).x[k], res.node(6).x[k]
        aA, aB = res.node(3).xdd[k], res.node(6).xdd[k]
        alpha = res.node(2).xdd[k, 0]
        u = (xB - xA) / np.linalg.norm(xB - xA)
        N = -mB * aB[0] / u[0]
        RB = N * u[1] + mB * G
        F = mA * (aA - g) - N * u
        tau = I * alpha + cross2(xA, F)
        scale = 1.0 + abs(N)
        assert abs(res.sigma[k, res.deformation_index(2, 1)] - N) <= 1e-10 * scale
        assert abs(res.reaction[k, res.coordinate_index(6, 2)] - RB) <= 1e-10 * scale
        assert np.abs(res.reaction[k, [res.coordinate_index(1, 1), res.coordinate_index(1, 2)]] - F).max() <= 1e-10 * scale
        assert abs(res.reaction[k, res.coordinate_index(2, 1)] - tau) <= 1e-10 * scale
        # The pinned rod carries no bending moments.
        assert abs(res.sigma[k, res.deformation_index(2, 2)]) <= 1e-10 * scale
        assert abs(res.sigma[k, res.deformation_index(2, 3)]) <= 1e-10 * scale


def test_rigid_pendulum_pivot_force_newton_euler():
    """Rigid PLBEAM pendulum with EMASS and a tip MASS swinging under gravity (DOF: β2): the
    pivot reaction is m a_c − m g, with a_c the acceleration of the centre of mass
    (m_tip a_tip + ρAL a_tip/2)."""
    m_tip, rho, L = 0.7, 1.3, 1.0
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, 0.6 * L, -0.8 * L)
    m.fix(1)
    m.mass(3, m_tip)
    m.emass(1, rho)
    m.gravity(0.0, -G)
    m.dynx(2, 1)
    m.xd(2, 1, 2.0)
    m.forcemode(2)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.timestep(10, 2.0)
    res = m.run()
    a_tip = res.node(3).xdd
    expected = m_tip * a_tip + 0.5 * rho * L * a_tip - (m_tip + rho * L) * np.array([0.0, -G])
    r = res.reaction[:, [res.coordinate_index(1, 1), res.coordinate_index(1, 2)]]
    assert np.abs(r - expected).max() <= 1e-10 * np.abs(expected).max()
    assert np.all(res.reaction[:, res.coordinate_index(2, 1)] == 0.0)  # DYNX: no reaction


# --------------------------------------------------------------------------------------------
# Consistency of (6.1) with the equations of motion (formulation.md §6)
# --------------------------------------------------------------------------------------------

def consistency(sim, t, q, qd):
    sim.evaluate(t, q, qd)
    sim.forces()
    d, s = sim.data, sim.system
    sigma, sig_eq, load = np.array(d.sigma), np.array(d.sigma_equilibrium), np.array(d.residual_load)
    scale = np.abs(np.array(d.reaction)).max() + np.abs(sigma).max()
    dof_stress = np.abs(sig_eq[s.e_dyn] - sigma[s.e_dyn]).max(initial=0.0)
    dof_rows = np.abs(load[s.x_dyn]).max(initial=0.0)
    calc_rows = np.abs(load[s.x_calc]).max(initial=0.0)
    reaction_rows = np.abs(load[s.x_fixed] - np.array(d.reaction)[s.x_fixed]).max(initial=0.0)
    return dof_stress / scale, dof_rows / scale, calc_rows / scale, reaction_rows


def test_reactions_consistent_with_the_motion_flexible_slider_crank():
    model = spacar.read_string(EXAMPLE.read_text())
    sim = assembled(model)
    rng = np.random.default_rng(5)
    for t in (0.0, 0.4, 1.3, 3.1):
        q = 1e-3 * rng.normal(size=4)
        qd = 1e-2 * rng.normal(size=4)
        dof_stress, _, calc_rows, reaction_rows = consistency(sim, t, q, qd)
        assert dof_stress <= 1e-12
        assert calc_rows <= 1e-12
        assert reaction_rows == 0.0
        # σ of the DOF rows from (6.1) is not trivially the constitutive value: off the
        # equations of motion (a wrong q̈) it differs.
    assert np.abs(np.array(sim.data.sigma)[sim.system.e_dyn]).max() > 0


def test_reactions_consistent_with_the_motion_dynx_pendulum():
    """A DYNX coordinate (β2 of a flexible double pendulum under gravity): its row of
    g + DDᵀσ vanishes, as do the calculable rows, and σ^d from (6.1) is constitutive."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 4, 5, 6)
    m.x(3, 0.6, -0.8)
    m.x(5, 1.2, -1.6)
    m.fix(1)
    m.dynx(2, 1)
    m.dyne(2, 2, 3)
    m.estiff(2, 0.0, 2.0)
    m.emass(1, 1.0)
    m.emass(2, 0.5)
    m.mass(5, 0.3)
    m.gravity(0.0, -G)
    sim = assembled(m)
    dof_stress, dof_rows, calc_rows, _ = consistency(sim, 0.0, np.array([0.3, 0.02, -0.01]), np.array([1.2, 0.1, 0.3]))
    assert dof_stress <= 1e-12 and dof_rows <= 1e-12 and calc_rows <= 1e-12
