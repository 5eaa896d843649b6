"""Models and closed-form references shared by the spatial dynamics and spatial input tests
(issue #4) and the spatial element tests: Euler-parameter matrices (formulation.md §0), the HINGE
reference frame (§4.10), the spatial RSSR/RSUR linkage with the closed-form solution of its loop
equation, the BEAM cantilever and its numerical linearization.
"""
from __future__ import annotations

import numpy as np

import spacar
from support.paths import EXAMPLES
from support.simulation import assembled

PLANAR_EXAMPLE = EXAMPLES / "slidercrank.dat"
SPATIAL_EXAMPLE = EXAMPLES / "slidercrank3d.dat"


# ---------------------------------------------------------------------------------------------
# Euler parameters (formulation.md §0)
# ---------------------------------------------------------------------------------------------

def E_(l):
    return np.array([[-l[1], l[0], -l[3], l[2]],
                     [-l[2], l[3], l[0], -l[1]],
                     [-l[3], -l[2], l[1], l[0]]])


def G_(l):
    return np.array([[-l[1], l[0], l[3], -l[2]],
                     [-l[2], -l[3], l[0], l[1]],
                     [-l[3], l[2], -l[1], l[0]]])


def R_(l):
    """Rotation body → global."""
    return E_(l) @ G_(l).T


def body_angular_velocity(lam, lamd):
    """ω′ = 2 G(λ) λ̇ for arrays of shape (nt, 4)."""
    return np.einsum("tij,tj->ti", 2.0 * np.array([G_(l) for l in lam]), lamd)


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def hinge_frame(axis):
    """§4.10: e_x0 = axis/|axis|; e_y0 = the global unit axis along which |e_x0| has its smallest
    component (ties → first), orthogonalised; e_z0 = e_x0 × e_y0."""
    ex = unit(axis)
    k = int(np.argmin(np.abs(np.asarray(axis, float))))  # argmin: first of equal minima
    y = unit(np.eye(3)[k] - ex[k] * ex)
    return np.column_stack([ex, y, np.cross(ex, y)])


def lambda_nodes(model):
    """Numbers of the LAMBDA nodes of a (prepared or not) model."""
    return sorted(n for n, node in model.nodes.items() if node.kind.name.upper() == "LAMBDA")


def tighten(model, eps=1e-11, epskin=1e-12):
    model.epsint(eps)
    model.epsind(eps)
    model.epskin(epskin)
    return model


# ---------------------------------------------------------------------------------------------
# Spatial four-bar RSSR (and RSUR): crank about uA through A, rocker about uD through D,
# skew axes. The closed form follows from |C(φ) − B(θ)|² = Lc²:
#   d = D − B(θ),  P cos φ + Q sin φ + R = 0  with  P = 2 r3 d·a3, Q = 2 r3 d·b3,
#   R = |d|² + r3² − Lc²  ⇒  φ = atan2(Q, P) + acos(−R / √(P² + Q²))   (the assembly branch)
# φ is the rocker angle from a3 towards b3 = uD × a3, i.e. right-handed about uD, which is the
# sense of HINGE e1 about the axis uD.
# ---------------------------------------------------------------------------------------------

class RSSR:
    A = np.zeros(3)
    uA = np.array([0.0, 0.0, 1.0])
    r1 = 0.2
    a1 = np.array([1.0, 0.0, 0.0])
    b1 = np.cross(uA, a1)
    D = np.array([0.4, 0.1, 0.6])
    uD = unit([1.0, 0.2, 0.1])
    r3 = 0.5
    a3 = unit(np.cross(uD, [0.0, 0.0, 1.0]))
    b3 = np.cross(uD, a3)
    Lc = 0.89  # the crank turns fully for 0.669 < Lc < 1.110

    @classmethod
    def B(cls, theta):
        return cls.A + cls.r1 * (np.cos(theta) * cls.a1 + np.sin(theta) * cls.b1)

    @classmethod
    def C(cls, phi):
        return cls.D + cls.r3 * (np.cos(phi) * cls.a3 + np.sin(phi) * cls.b3)

    @classmethod
    def loop_coefficients(cls, theta, Lc=None):
        Lc = cls.Lc if Lc is None else Lc
        d = cls.D - cls.B(theta)
        return 2 * cls.r3 * d @ cls.a3, 2 * cls.r3 * d @ cls.b3, d @ d + cls.r3**2 - Lc**2

    @classmethod
    def phi(cls, theta, Lc=None):
        P, Q, R = cls.loop_coefficients(theta, Lc)
        return np.arctan2(Q, P) + np.arccos(-R / np.hypot(P, Q))

    @classmethod
    def rocker_angle(cls, theta):
        """Closed-form rocker rotation from the initial position (θ = 0), continuous in θ."""
        theta = np.atleast_1d(theta)
        return np.unwrap([cls.phi(t) for t in theta]) - cls.phi(0.0)


def rssr_model(coupler="truss", dynamic=False, rate=1.5, n_out=200, period=10.0):
    """RSSR (coupler = TRUSS: spherical joints at both ends) or RSUR (coupler = BEAM, spherical
    joint at the crank: crank and coupler share the XYZ node 2 but have their own LAMBDA nodes
    12 and 17; universal joint at the rocker: HINGEs 7 and 8 with perpendicular axes through
    the cross 15). Crank BEAM 1 (A = node 1 → B = node 2) on HINGE 5 to the ground orientation
    10, rocker BEAM 2 (D = node 4 → C = node 3) on HINGE 6. Kinematic: crank angle INPUTE at
    `rate`; dynamic: crank angle DYNE with initial rate `rate`, distributed masses, a point mass
    at C, a rigid body on the coupler, gravity along −z."""
    g = RSSR
    B0, C0 = g.B(0.0), g.C(g.phi(0.0))
    m = spacar.Model()
    m.beam(1, 1, 11, 2, 12, *g.uA)
    m.beam(2, 4, 13, 3, 14, *g.uD)
    m.hinge(5, 10, 11, *g.uA)
    m.hinge(6, 10, 13, *g.uD)
    if coupler == "truss":
        m.truss(3, 2, 3)
    else:
        u1 = g.uD
        u2 = unit(np.cross(u1, C0 - B0))
        m.beam(3, 2, 17, 3, 16, *u1)
        m.hinge(7, 14, 15, *u1)
        m.hinge(8, 15, 16, *u2)
        m.rlse(7, 1)
        m.rlse(8, 1)
    m.x(1, *g.A)
    m.x(2, *B0)
    m.x(3, *C0)
    m.x(4, *g.D)
    m.fix(1)
    m.fix(4)
    m.fix(10)
    m.rlse(6, 1)
    if dynamic:
        m.dyne(5, 1)
        for e, rho in ((1, 1.0), (2, 0.8), (3, 0.5)):
            m.emass(e, rho)
        m.mass(3, 0.2)
        if coupler != "truss":
            m.mass(16, 0.01, 0.0, 0.0, 0.02, 0.0, 0.03)
        m.gravity(0.0, 0.0, -9.81)
    else:
        m.inpute(5, 1)
    m.ed(5, 1, rate)
    m.timestep(n_out, period)
    return m


# ---------------------------------------------------------------------------------------------
# BEAM cantilever along x, clamped at node 1 / LAMBDA 101: n elements, e1 rigid, torsion and
# bending DYNE; local y = global y.
# ---------------------------------------------------------------------------------------------

def cantilever(n, EIy=1.0, EIz=4.0, GIp=1.0, rhoA=1.0, rhoIp=0.01, L=1.0):
    m = spacar.Model()
    for i in range(n):
        m.beam(i + 1, i + 1, 101 + i, i + 2, 102 + i, 0.0, 1.0, 0.0)
    for i in range(n + 1):
        m.x(i + 1, L * i / n, 0.0, 0.0)
    m.fix(1)
    m.fix(101)
    for i in range(n):
        m.dyne(i + 1, 2, 3, 4, 5, 6)
        m.estiff(i + 1, 0.0, GIp, EIy, EIz)
        m.emass(i + 1, rhoA, rhoIp, 0.0, 0.0)
    m.epskin(1e-13)
    return m


def linearize(model, h=1e-9):
    """M̄ = data.Mbar and K = −M̄ ∂q̈/∂q by central differences of Simulation.evaluate at the
    assembled state with q̇ = 0. Returns (M̄, K, labels) with labels[j] = (element, deformation)
    of DOF j."""
    sim = assembled(model)
    system = sim.system
    nd = system.n_dof
    q0 = np.array(system.q0)
    zero = np.zeros(nd)
    sim.evaluate(0.0, q0, zero)
    Mbar = np.array(sim.data.Mbar)
    dqdd = np.empty((nd, nd))
    for j in range(nd):
        qp, qm = q0.copy(), q0.copy()
        qp[j] += h
        qm[j] -= h
        sim.evaluate(0.0, qp, zero)
        a = np.array(sim.data.qdd)
        sim.evaluate(0.0, qm, zero)
        b = np.array(sim.data.qdd)
        dqdd[:, j] = (a - b) / (2 * h)
    labels = [tuple(system.def_label[k]) for k in system.e_dyn]
    return Mbar, -Mbar @ dqdd, labels


def bathe_bend(n, element="beam"):
    """Bathe and Bolourchi's 45° bend: a cantilever of radius 100 over 45° in the x–y plane, unit
    square section (E = 1e7, G J = 0.5 E · 0.1406), n beams of ``element`` with all their
    deformations DYNE, a tip load of 600 out of its plane (along z). Published tip: about (47.2,
    15.8, 53.4) (Simo and Vu-Quoc; Crisfield; the torsion constant differs between them)."""
    R, E = 100.0, 1e7
    m = spacar.Model()
    for i in range(n):
        getattr(m, element)(i + 1, i + 1, 1001 + i, i + 2, 1002 + i, 0.0, 0.0, 1.0)
        m.dyne(i + 1, 1, 2, 3, 4, 5, 6)
        m.estiff(i + 1, E, 0.5 * E * 0.1406, E / 12, E / 12)
    for i in range(n + 1):
        a = np.pi / 4 * i / n
        m.x(i + 1, R * np.sin(a), R * (1 - np.cos(a)), 0.0)
    m.fix(1)
    m.fix(1001)
    m.force(n + 1, 0.0, 0.0, 600.0)
    return m
