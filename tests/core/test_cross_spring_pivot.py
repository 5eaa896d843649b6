"""A planar cross-spring pivot (issue 19): two steel leaves of length L at ±45°, each clamped to
the ground at its lower end and to a rigid rotating body at its upper end, crossing at a
distance a from the body ends (a = L/2: at their midpoints). Checked against small-deflection
formulas derived below (the classic results of Haringx 1949, "The cross-spring pivot as a
constructional element", Appl. Sci. Res. A1, and Wittrick 1951, Aeronaut. Q. 2, for the
influence of the crossing point): the rotational stiffness, its change under a vertical load on
the body, and the centre shift.

Derivation (Euler-Bernoulli leaves, axially rigid to first order). The axes of both leaves pass
through the crossing point, so the body's instantaneous centre of rotation is that point: a body
rotation θ moves a leaf's upper end by v = a θ across the leaf and turns it by θ. A leaf clamped
at s = 0 with end displacement v and slope θ at s = L stores
    U = EI/L³ (6 v² − 6 v L θ + 2 L² θ²)          (its 4 × 4 bending stiffness, base fixed)
      = EI θ²/L (6 α² − 6 α + 2),  α = a/L,
so the pivot's rotational stiffness is K = 2 · 2U/θ² = (2 EI/L)(12 α² − 12 α + 4): K = 2 EI/L at
the midpoints (each leaf bends into a circular arc under a constant moment EI θ/L, with no shear
force), the least of any crossing, and 8 EI/L (two leaves of 4 EI/L) when the leaves cross at
the body (α = 0): 8 EI/L is the end-crossing value, not the midpoint one.

Under a dead vertical load P (downward, positive) shared by the two upper leaf ends (height
y = a/√2 above the crossing), each leaf carries the axial force N = −P/√2. To first order in P
the stiffness changes by the second-order work of the loads along the first-order mode:
    ΔK = Σ N (∫v'² ds / θ² − a) − P a/√2,
with ∫v'² ds = θ² L/3 on the midpoint arc (v' = θ s/L), the −a from the upper end's rigid-body
rotation (it moves towards the ground by θ² a/2) and the last term the load's own fall. At
a = L/2: ΔK = P L (a/√2 − √2 L/3)/L = −P L/(6√2) (compression softens, tension stiffens).

Centre shift: the inextensible leaves shorten by ∫v'²/2 = θ² L/6 while the rotation alone would
bring their ends θ² a/2 = θ² L/4 closer to the ground, so the body rises by δ with
δ/√2 = θ² (L/4 − L/6): the body point at the crossing drifts up by θ² L/(6√2), O(θ²)."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import section

from support.flexures import BETA, BODY, DIRECTIONS, L, pivot, stiffness


def load(m, P):
    """The dead vertical load P (downward) shared by the body's two upper leaf ends."""
    m.force(BODY, 0.0, -P / 2)
    m.force(BODY + 100, 0.0, -P / 2)


@pytest.mark.parametrize("alpha", [0.5, 0.3])
def test_rotational_stiffness(alpha):
    m, EI = pivot(alpha=alpha)
    K = stiffness(m)
    assert K == pytest.approx(2 * EI / L * (12 * alpha**2 - 12 * alpha + 4), rel=1e-4)
    if alpha == 0.5:
        assert K == pytest.approx(2 * EI / L, rel=1e-6)   # constant curvature: exact in the cubic elements
    m.force(BETA, 0.01 * K)                               # a moment on the body's BETA node
    theta = spacar.static(m, steps=1).node(BETA).x[-1][0]
    assert theta == pytest.approx(0.01, rel=1e-4)


def test_stiffness_under_a_vertical_load():
    """PLBEAMNL: the leaves' axial force acts on their bending within each element (PLBEAM keeps
    only the chord rotations: 1.5 % off the coefficient with 8 elements)."""
    K0 = stiffness(pivot("plbeamnl")[0])
    P, K = 20.0, {}
    for p in (P, -P):
        m, _ = pivot("plbeamnl")
        load(m, p)
        spacar.static(m, steps=1)
        K[p] = stiffness(m)
    # Compression softens, tension stiffens; the odd part is the first-order term (up to P³).
    assert K[P] < K0 < K[-P]
    assert (K[P] - K[-P]) / 2 == pytest.approx(-P * L / (6 * np.sqrt(2)), rel=2e-3)
    for p in (P, -P):
        # The tangent against a central difference of static solutions under ± a small moment.
        thetas = []
        for M in (1e-3 * K0, -1e-3 * K0):
            m, _ = pivot("plbeamnl")
            load(m, p)
            m.force(BETA, M)
            thetas.append(spacar.static(m, steps=1).node(BETA).x[-1][0])
        assert 2e-3 * K0 / (thetas[0] - thetas[1]) == pytest.approx(K[p], rel=1e-5)


def test_centre_shift_is_second_order():
    K0 = stiffness(pivot("plbeamnl")[0])
    drift = {}
    for theta in (0.01, 0.02):
        m, _ = pivot("plbeamnl")
        m.force(BETA, K0 * theta)
        res = spacar.static(m, steps=2)
        x, beta = res.node(BODY).x[-1], res.node(BETA).x[-1][0]
        turn = np.array([[np.cos(beta), -np.sin(beta)], [np.sin(beta), np.cos(beta)]])
        crossing = x - turn @ (L / 2 * DIRECTIONS[0])       # the body point at the crossing
        assert abs(crossing[0]) < 1e-2 * abs(crossing[1])   # it rises, hardly sideways
        assert crossing[1] == pytest.approx(beta**2 * L / (6 * np.sqrt(2)), rel=1e-3)
        drift[theta] = np.hypot(*crossing)
    assert drift[0.02] / drift[0.01] == pytest.approx(4.0, rel=1e-3)
