"""Planar models shared by test folders."""
from __future__ import annotations

import spacar


def compressed_cantilever(n):
    """n PLBEAMNLs along x from the clamped nodes 1 (XY), 2 (BETA) to the tip node 2n+1, of unit
    length, EI = ρA = 1 and bending deformations DYNE, under a unit compressive tip force, with
    LINEAR 2 (linearized at every output time, buckling included); no TIMESTEP."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeamnl(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n, 0.0)
        m.emass(k, 1.0)
        m.estiff(k, 0.0, 1.0)
        m.dyne(k, 2, 3)
    m.fix(1)
    m.fix(2)
    m.force(2 * n + 1, -1.0, 0.0)
    m.linear(2)
    return m


def tip_loaded_beam(n, L=1.2, EI=2.0, rhoA=3.0, EA=1e4):
    """n PLBEAMs along x clamped at nodes 1/2, all deformations DYNE (elongation stiff), tip node
    2n+1 with a force input and position and rate outputs."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k * L / n, 0.0)
        m.estiff(k, EA, EI)
        m.emass(k, rhoA)
        m.dyne(k, 1, 2, 3)
    m.fix(1)
    m.fix(2)
    tip = 2 * n + 1
    m.inputf(1, tip, 2)
    m.outx(1, tip, 2)
    m.outxp(2, tip, 2)
    return m


def spring_mass(mass=2.0, k=50.0, c=0.7):
    """A mass on a PLTRUSS spring-damper of unit length along x: x of node 2 the DOF."""
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(1, 0.0, 0.0)
    m.x(2, 1.0, 0.0)
    m.fix(1)
    m.fix(2, 2)
    m.dynx(2, 1)
    m.rlse(1)
    m.estiff(1, k)
    m.edampp(1, c)
    m.mass(2, mass)
    m.inputf(1, 2, 1)
    m.inputs(2, 1, 1)
    m.outx(1, 2, 1)
    m.outxp(2, 2, 1)
    m.oute(3, 1, 1)
    m.outep(4, 1, 1)
    return m


def leaf_guide(L, D, n):
    """Two leaves of n PLBEAMs along y (x = 0 and x = D), clamped at the ground, welded to a rigid
    stage (PLBEAM 2n + 1) whose x at node 2n + 1 is fixed: its support stiffness along x is the
    drive stiffness of the guide."""
    m = spacar.Model()
    e = 0
    for leaf, x0 in enumerate((0.0, D)):
        base = 100 * leaf
        for i in range(n):
            e += 1
            m.plbeam(e, base + 2 * i + 1, base + 2 * i + 2, base + 2 * i + 3, base + 2 * i + 4)
            m.rlse(e)
        for i in range(n + 1):
            m.x(base + 2 * i + 1, x0, L * i / n)
        m.fix(base + 1)
        m.fix(base + 2)
        for node in range(base + 3, base + 2 * n + (3 if leaf == 0 else 1)):  # leaf 2's top follows the stage
            m.dynx(node)
    top = 2 * n + 1
    m.plbeam(e + 1, top, top + 1, 100 + top, 100 + top + 1)  # the rigid stage
    m.fix(top, 1)
    return m
