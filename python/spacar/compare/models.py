"""Parametrised spacar models used by the cross-checks (tests/peers/test_compare.py) and the
benchmarks (benchmarks/*.py): pendulum chains, a four-bar linkage, a flexible cantilever and the
manual's slider-crank with a refinable connecting rod. Every function returns a new
:class:`spacar.Model`; none needs a peer library.
"""
from __future__ import annotations

import math

import numpy as np

from ..model import Model

G = 9.81

# Numbering of the chains: links (beams) 1..n from position node i to i+1; BETA/LAMBDA nodes
# START + i (start of link i) and END + i (end of link i; END + 0 is the ground's); hinges
# HINGE + i. The offsets leave room for n < 100000 links.
START, END, HINGE = 100000, 200000, 300000


def _tolerances(m: Model, eps, epskin):
    m.epsint(eps)
    m.epsind(eps)
    m.epskin(epskin)


def planar_chain(n: int, length: float = 1.0, rho_a: float = 1.0, tip_mass: float = 0.0,
                 joint_inertia: float = 0.0, angle: float = 0.0, dof: str = "relative",
                 stiffness: float = 0.0, damping: float = 0.0, ground_angle: float = 0.0,
                 gravity=(0.0, -G), t_end: float = 1.0, n_out: int = 10, eps: float = 1e-8,
                 epskin: float = 1e-10) -> Model:
    """An n-link planar pendulum chain of total ``length``, released from rest at ``angle``
    (rad, from the +x axis) under gravity.

    Link i is a rigid PLBEAM i from position node i to i+1 with the BETA nodes START+i (start)
    and END+i (end) — both rotate with the link — and EMASS ``rho_a``; ``tip_mass`` is a MASS on
    every position node 2..n+1, ``joint_inertia`` a MASS (Izz) on every BETA node START+i. The
    joints are PLHINGE HINGE+i from node END+i−1 to START+i (node END is the fixed ground BETA
    node, at ``ground_angle``); ``dof="relative"`` makes their e1 the DOFs (DYNE: Pinocchio's q,
    relative joint angles), ``dof="absolute"`` the link rotations (DYNX on START+i).
    ``stiffness``/``damping``: ESTIFF/EDAMPP of the hinges."""
    m = Model()
    step = length / n
    c, s = math.cos(angle), math.sin(angle)
    m.x(1, 0.0, 0.0)
    for i in range(1, n + 1):
        m.plbeam(i, i, START + i, i + 1, END + i)
        m.x(i + 1, i * step * c, i * step * s)
        m.plhinge(HINGE + i, END + i - 1, START + i)
        if dof == "relative":
            m.dyne(HINGE + i, 1)
        elif dof == "absolute":
            m.rlse(HINGE + i, 1)
            m.dynx(START + i, 1)
        else:
            raise ValueError("dof must be 'relative' or 'absolute'")
        if rho_a:
            m.emass(i, rho_a)
        if tip_mass:
            m.mass(i + 1, tip_mass)
        if joint_inertia:
            m.mass(START + i, joint_inertia)
        if stiffness or damping:
            m.estiff(HINGE + i, stiffness)
            m.edampp(HINGE + i, damping)
    m.fix(1)
    m.fix(END)
    if ground_angle:
        m.beta(END, ground_angle)
    if gravity is not None and any(gravity):
        m.gravity(*gravity)
    _tolerances(m, eps, epskin)
    m.timestep(n_out, t_end)
    return m


def _box_inertia(mass, a, b, c):
    return mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def spatial_chain(n: int, seed: int = 0, joints: str = "hinge", t_end: float = 0.5, n_out: int = 5,
                  eps: float = 1e-9, epskin: float = 1e-11, ground_rotation: bool = True,
                  stiffness: float = 0.0) -> Model:
    """An n-link spatial chain with random (seeded) geometry, numbered as the planar chain: rigid
    BEAM i from node i to i+1 with LAMBDA nodes START+i and END+i, EMASS ρA with rotary inertia,
    a point MASS at every node 2..n+1 and a full inertia tensor (MASS on LAMBDA START+i, a
    rotated box). Joints: ``"hinge"`` — HINGE HINGE+i from LAMBDA END+i−1 to START+i about a
    random axis, e1 DYNE (relative angles; node END is the fixed ground LAMBDA node, rotated by
    0.4 rad about a random axis if ``ground_rotation``); ``"spherical"`` — shared position nodes
    only, DYNX on the LAMBDA nodes START+i (Euler parameters as DOFs). Gravity along a random
    direction."""
    rng = np.random.default_rng(seed)
    m = Model()
    p = np.array([0.1, -0.2, 0.3])
    m.xyz(1, *p)
    for i in range(1, n + 1):
        d = rng.normal(size=3)
        d *= (0.4 + 0.4 * rng.random()) / np.linalg.norm(d)
        v = np.cross(d, rng.normal(size=3))
        m.beam(i, i, START + i, i + 1, END + i, *v)
        p = p + d
        m.xyz(i + 1, *p)
        if joints == "hinge":
            m.hinge(HINGE + i, END + i - 1, START + i, *rng.normal(size=3))
            m.dyne(HINGE + i, 1)
            if stiffness:
                m.estiff(HINGE + i, stiffness)
        elif joints == "spherical":
            m.dynx(START + i)
        else:
            raise ValueError("joints must be 'hinge' or 'spherical'")
        m.emass(i, 1.0 + rng.random(), 1e-3, 2e-3, 3e-3)
        m.mass(i + 1, 0.2 + 0.3 * rng.random())
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        J = Q @ _box_inertia(0.5, *(0.1 + 0.2 * rng.random(3))) @ Q.T
        m.mass(START + i, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
    m.fix(1)
    if joints == "hinge":
        m.fix(END)
        if ground_rotation:
            # a moderate rotation (0.4 rad about a random axis): the assembly starts from the
            # given positions with the links' LAMBDA nodes at the reference and must converge
            u = rng.normal(size=3)
            u /= np.linalg.norm(u)
            m.lambda_(END, math.cos(0.2), *(math.sin(0.2) * u))
    g = rng.normal(size=3)
    m.gravity(*(G * g / np.linalg.norm(g)))
    _tolerances(m, eps, epskin)
    m.timestep(n_out, t_end)
    return m


def seven_r_loop(seed: int = 2, crank_rate: float = 1.0, t_end: float = 1.0, n_out: int = 10, eps: float = 1e-8,
                 epskin: float = 1e-13, dof: int = 1, last: int = 7) -> Model:
    """A spatial 7R loop: a random (seeded) 6-link chain as :func:`spatial_chain` (rigid BEAMs
    with EMASS and rotary inertia, point masses, inertia tensors, gravity along a random
    direction) whose HINGE ``dof`` (1 … 6, the first by default) is the DOF (initial rate
    ``crank_rate``) and whose other HINGEs are released (passive), its tip node fixed to the ground and a seventh HINGE (e1 released, e2
    and e3 rigid) from the last link's LAMBDA node to the ground's about a random axis. The loop
    closes at a point and at a hinge: five constraints for five passive joints, mobility one.
    The seed's geometry keeps the loop away from its locking positions over 1 s. HINGE ``i``
    (1 … 7) is element HINGE + i, except HINGE ``last`` (if not the seventh), numbered HINGE + 8:
    the recursive path cuts the loop at the passive hinge of the highest number (the seventh, to
    the ground, by default; ``last`` = 4 cuts it between two moving links)."""
    if not (1 <= dof <= 6 and 1 <= last <= 7):
        raise ValueError(f"seven_r_loop: dof must be 1 … 6 and last 1 … 7, got {dof} and {last}")
    rng = np.random.default_rng(seed)
    hinge = {i: HINGE + (8 if i == last != 7 else i) for i in range(1, 8)}
    m = Model()
    p = np.array([0.1, -0.2, 0.3])
    m.xyz(1, *p)
    n = 6
    for i in range(1, n + 1):
        d = rng.normal(size=3)
        d *= (0.4 + 0.4 * rng.random()) / np.linalg.norm(d)
        m.beam(i, i, START + i, i + 1, END + i, *np.cross(d, rng.normal(size=3)))
        p = p + d
        m.xyz(i + 1, *p)
        m.hinge(hinge[i], END + i - 1, START + i, *rng.normal(size=3))
        (m.dyne if i == dof else m.rlse)(hinge[i], 1)
        m.emass(i, 1.0 + rng.random(), 1e-3, 2e-3, 3e-3)
        m.mass(i + 1, 0.2 + 0.3 * rng.random())
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        J = Q @ np.diag(0.05 + 0.1 * rng.random(3)) @ Q.T
        m.mass(START + i, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
    m.hinge(hinge[n + 1], END + n, END, *rng.normal(size=3))
    m.rlse(hinge[n + 1], 1)
    m.fix(1)
    m.fix(n + 1)
    m.fix(END)
    g = rng.normal(size=3)
    m.gravity(*(G * g / np.linalg.norm(g)))
    m.ed(hinge[dof], 1, crank_rate)
    _tolerances(m, eps, epskin)
    m.timestep(n_out, t_end)
    return m


def four_bar(crank_speed: float = 2.0, t_end: float = 1.0, n_out: int = 10, eps: float = 1e-8,
             epskin: float = 1e-10) -> Model:
    """A free four-bar linkage under gravity: ground pivots at nodes 1 (0, 0) and 4 (2.5, 0),
    crank PLBEAM 1 (1 → 2, length 1), coupler PLBEAM 2 (2 → 3), rocker PLBEAM 3 (4 → 3);
    EMASS 1.0, 1.5, 1.2 and a MASS 0.3 at the coupler–rocker joint; DOF: the crank rotation
    (DYNX on BETA 11) with initial rate ``crank_speed``."""
    m = Model()
    m.plbeam(1, 1, 11, 2, 12)
    m.plbeam(2, 2, 21, 3, 22)
    m.plbeam(3, 4, 31, 3, 32)
    m.x(1, 0.0, 0.0)
    m.x(2, 0.0, 1.0)
    m.x(3, 2.0, 1.5)
    m.x(4, 2.5, 0.0)
    m.fix(1)
    m.fix(4)
    m.dynx(11, 1)
    for e, r in ((1, 1.0), (2, 1.5), (3, 1.2)):
        m.emass(e, r)
    m.mass(3, 0.3)
    m.xd(11, 1, crank_speed)
    m.gravity(0.0, -G)
    _tolerances(m, eps, epskin)
    m.timestep(n_out, t_end)
    return m


def cantilever(n: int, length: float = 1.0, ei: float = 25.0, rho_a: float = 1.0, t_end: float = 0.1,
               n_out: int = 1, eps: float = 1e-6, epskin: float = 1e-10) -> Model:
    """A flexible cantilever of n PLBEAM elements along +x, clamped at node 1 (BETA node
    10001 fixed), axially rigid (e1 fixed), bending deformations DYNE (2n DOFs), EMASS ρA,
    ESTIFF EI; released from the straight state under gravity (static tip deflection
    ρA g L⁴/8EI = 5 % of L with the defaults)."""
    m = Model()
    step = length / n
    for i in range(1, n + 1):
        m.plbeam(i, i, 10000 + i, i + 1, 10000 + i + 1)
        m.x(i + 1, i * step, 0.0)
        m.dyne(i, 2, 3)
        m.estiff(i, 0.0, ei)
        m.emass(i, rho_a)
    m.fix(1)
    m.fix(10001)
    m.gravity(0.0, -G)
    _tolerances(m, eps, epskin)
    m.timestep(n_out, t_end)
    return m


def slider_crank(n_rod: int = 2, t_end: float = 5.0, n_out: int = 100, eps: float = 1e-3,
                 epskin: float = 1e-5) -> Model:
    """The SPACAR95 manual's slider-crank (§5.7; examples/slidercrank.dat for n_rod = 2) with
    the connecting rod (length 0.30) divided into ``n_rod`` PLBEAM elements (n_rod even, so that
    a node sits at the rod's middle). Crank: PLBEAM 1 (nodes 1, 2, 3, 4), driven at 1.5 rad/s
    (INPUTX 2); rod: PLBEAM 2..n_rod+1 from node 3 to the slider node 8 (FIX 8 2, MASS
    0.033375), BETA node 5 at the crank pin, 9 at the slider, interior nodes 100+k (position)
    and 200+k (BETA); bending DYNE, EI 0.0012723, ρA 0.2225. The rod's middle node is 6 (BETA
    7) as in the manual."""
    if n_rod < 2 or n_rod % 2:
        raise ValueError("n_rod must be even and at least 2")
    m = Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, 0.15, 0.0)
    l = 0.30 / n_rod
    pos = [3] + [100 + k for k in range(1, n_rod)] + [8]
    beta = [5] + [200 + k for k in range(1, n_rod)] + [9]
    pos[n_rod // 2], beta[n_rod // 2] = 6, 7
    for k in range(n_rod):
        e = 2 + k
        m.plbeam(e, pos[k], beta[k], pos[k + 1], beta[k + 1])
        m.dyne(e, 2, 3)
        m.emass(e, 0.2225)
        m.estiff(e, 0.0, 0.0012723)
    for k in range(1, n_rod + 1):
        m.x(pos[k], 0.15 + k * l, 0.0)
    m.fix(1)
    m.fix(8, 2)
    m.inputx(2, 1)
    m.xd(2, 1, 1.5)
    m.mass(8, 0.033375)
    m.emass(1, 0.2225)
    _tolerances(m, eps, epskin)
    m.timestep(n_out, t_end)
    return m
