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
