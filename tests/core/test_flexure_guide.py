"""A parallel leaf-spring guide designed with spacar.section, spacar.static, spacar.compliance,
section.stresses and the buckling modes (issue 19; the worked example of docs/statics.md),
against the small-deflection formulas of flexure design computed here: drive stiffness
24 EI/L³, its drop by 6P/5L under a compressive load P on the stage, the largest bending stress
3 E t u / L² at a drive displacement u, and the buckling load 2π²EI/L² of the two clamped-guided
leaves (sway mode)."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import section

N, L, D, B, T = 8, 0.05, 0.03, 0.02, 0.0005   # 8 elements per leaf, 50 mm long, 30 mm apart, 20 x 0.5 mm


def leaf_guide(element="plbeam"):
    """Two steel leaves along y at x = 0 and x = D (nodes 1.. and 101..), clamped at y = 0, their
    tops joined by a rigid stage (element 2N + 1: nodes 2N+1, 2N+2 — 2N+101, 2N+102). The leaves'
    deformations RLSE with the section's stiffness; their free nodes DYNX (leaf 2's top follows
    the stage)."""
    m = spacar.Model()
    leaf = section.rectangle(B, T, section.STEEL)
    for side, (x0, base) in enumerate([(0.0, 0), (D, 100)]):
        for k in range(1, N + 1):
            e = side * N + k
            getattr(m, element)(e, base + 2 * k - 1, base + 2 * k, base + 2 * k + 1, base + 2 * k + 2)
            m.x(base + 2 * k + 1, x0, k * L / N)
            m.rlse(e)
        m.x(base + 1, x0, 0.0)
        m.fix(base + 1)
        m.fix(base + 2)
        for k in range(1, (N if side == 0 else N - 1) + 1):
            m.dynx(base + 2 * k + 1)
            m.dynx(base + 2 * k + 2)
    leaf.apply(m)
    m.plbeam(2 * N + 1, 2 * N + 1, 2 * N + 2, 2 * N + 101, 2 * N + 102)  # rigid: no RLSE, no DYNE
    return m, leaf


STAGE = 2 * N + 1


def test_drive_stiffness_and_stress():
    m, leaf = leaf_guide()
    EI = leaf.plbeam_estiff()[1]
    k0 = 1.0 / spacar.compliance(m, STAGE)[0, 0]
    assert k0 == pytest.approx(24 * EI / L**3, rel=5e-4)   # (the leaves' axial compliance: 3e-4)
    m.force(STAGE, 1.0, 0.0)
    res = spacar.static(m, steps=2)
    u = res.node(STAGE).x[-1][0]
    assert u == pytest.approx(1.0 / k0, rel=1e-3)
    s = section.stresses(res, {e: leaf for e in range(1, 2 * N + 1)})
    value, element, _ = s.max()["normal"]
    assert element in (1, N, N + 1, 2 * N)                    # at a clamped end of a leaf
    assert value == pytest.approx(3 * section.STEEL.E * T * u / L**2, rel=1e-2)


def test_drive_stiffness_drops_under_a_compressive_stage_load():
    P = 1.0
    free, leaf = leaf_guide()
    k0 = 1.0 / spacar.compliance(free, STAGE)[0, 0]
    loaded, _ = leaf_guide()
    loaded.force(STAGE, 0.0, -P / 2)
    loaded.force(STAGE + 100, 0.0, -P / 2)
    spacar.static(loaded, steps=1)
    k = 1.0 / spacar.compliance(loaded, STAGE)[0, 0]
    assert k0 - k == pytest.approx(6 * P / (5 * L), rel=2e-2)


def test_buckling_load_of_the_guide():
    m, leaf = leaf_guide("plbeamnl")
    EI = leaf.plbeam_estiff()[1]
    m.force(STAGE, 0.0, -0.5)
    m.force(STAGE + 100, 0.0, -0.5)
    res = spacar.static(m, steps=1)     # G0 needs the stresses of the loaded equilibrium
    mu, _, shapes_x = spacar.linearize(m).buckling_modes()
    assert mu[0] == pytest.approx(2 * np.pi**2 * EI / L**2, rel=1e-3)
    # The sway mode: the stage moves sideways, not down.
    dx, dy = shapes_x[res.coordinate_index(STAGE, 1), 0], shapes_x[res.coordinate_index(STAGE, 2), 0]
    assert abs(dy) < 1e-3 * abs(dx)
