"""The flexure models written by hand (nodes, PLBEAMs, classes keyword by keyword), shared by
their tests (tests/core/test_flexure_guide.py, test_cross_spring_pivot.py, whose docstrings derive
the closed forms) and the flexure builder's (tests/api/test_flexure_builder.py): 8 steel leaves
of 50 x 20 x 0.5 mm."""
from __future__ import annotations

import numpy as np

import spacar
from spacar import section

N, L, D, B, T = 8, 0.05, 0.03, 0.02, 0.0005   # 8 elements per leaf, 50 mm long, 30 mm apart, 20 x 0.5 mm


def two_leaves(element, starts, directions):
    """Two steel leaves of N elements from the points ``starts`` along the unit ``directions``
    (nodes 1.. and 101..), clamped at their starts, their far ends joined by a rigid body
    (element 2N + 1: nodes 2N+1, 2N+2 — 2N+101, 2N+102; no RLSE, no DYNE) whose BETA nodes they
    share. The leaves' deformations RLSE with the section's stiffness; their free nodes DYNX
    (leaf 2's far end follows the body). Returns the model and the section."""
    m = spacar.Model()
    leaf = section.rectangle(B, T, section.STEEL)
    for side, (start, d, base) in enumerate(zip(starts, directions, (0, 100))):
        start, d = np.asarray(start, dtype=float), np.asarray(d, dtype=float)
        for k in range(1, N + 1):
            e = side * N + k
            getattr(m, element)(e, base + 2 * k - 1, base + 2 * k, base + 2 * k + 1, base + 2 * k + 2)
            m.x(base + 2 * k + 1, *(start + k * L / N * d))
            m.rlse(e)
        m.x(base + 1, *start)
        m.fix(base + 1)
        m.fix(base + 2)
        for k in range(1, (N if side == 0 else N - 1) + 1):
            m.dynx(base + 2 * k + 1)
            m.dynx(base + 2 * k + 2)
    leaf.apply(m)
    m.plbeam(2 * N + 1, 2 * N + 1, 2 * N + 2, 2 * N + 101, 2 * N + 102)
    return m, leaf


def leaf_guide(element="plbeam"):
    """The parallel guide: two leaves along y at x = 0 and x = D, clamped at y = 0, their tops
    joined by the rigid stage (node STAGE, its BETA node STAGE + 1)."""
    return two_leaves(element, [(0.0, 0.0), (D, 0.0)], [(0.0, 1.0), (0.0, 1.0)])


STAGE = 2 * N + 1

DIRECTIONS = (np.array([1.0, 1.0]) / np.sqrt(2), np.array([-1.0, 1.0]) / np.sqrt(2))
BODY, BETA = 2 * N + 1, 2 * N + 2    # the body's node at leaf 1's upper end, its rotation


def pivot(element="plbeam", alpha=0.5):
    """The cross-spring pivot: the leaves along DIRECTIONS, crossing at the origin at a = αL from
    their upper ends, clamped at their lower ends, the rigid body joining the upper ends.
    Returns the model and EI."""
    m, leaf = two_leaves(element, [-(1 - alpha) * L * d for d in DIRECTIONS], DIRECTIONS)
    return m, leaf.plbeam_estiff()[1]


def stiffness(m):
    return 1.0 / spacar.compliance(m, BETA)[0, 0]
