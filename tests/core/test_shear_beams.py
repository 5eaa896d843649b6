"""Shear-flexible (Timoshenko) beams (issue 39): ESTIFF of PLBEAM with a third value kGA and of
BEAM with a fifth and sixth, kGAy and kGAz (absent or 0: shear-rigid, as before). Against the
closed forms: a cantilever's tip compliance L³/(3EI) + L/(kGA), L²/(2EI), L/(EI) with one element
and with a mesh (the element is exact for constant shear), in both planes of the spatial beam
(bending about y shears along z), and the drive stiffness of a short parallel leaf-spring guide,
2/(L³/(12 EI) + L/(kGA)), against Timoshenko's clamped-guided leaf."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from support.planar_models import leaf_guide


def planar_cantilever(n, L, EA, EI, kGA=None):
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k * L / n, 0.0)
        m.rlse(k)
        m.estiff(k, EA, EI, *([] if kGA is None else [kGA]))
    m.fix(1)
    m.fix(2)
    for node in range(3, 2 * n + 3):
        m.dynx(node)
    return m, 2 * n + 1, 2 * n + 2


@pytest.mark.parametrize("n", [1, 6])
@pytest.mark.parametrize("kGA", [None, 0.0, 35.0, 2e3])
def test_planar_cantilever_compliance_is_timoshenko_s(n, kGA):
    L, EA, EI = 0.3, 4e5, 2.0
    model, tip, rotation = planar_cantilever(n, L, EA, EI, kGA)
    C = spacar.compliance(model, tip, rotation)
    shear = L / kGA if kGA else 0.0
    expected = np.array([[L / EA, 0.0, 0.0],
                         [0.0, L**3 / (3 * EI) + shear, L**2 / (2 * EI)],
                         [0.0, L**2 / (2 * EI), L / EI]])
    np.testing.assert_allclose(C, expected, rtol=1e-10, atol=1e-12 * np.abs(expected).max())


def test_spatial_cantilever_shears_in_both_planes():
    """BEAM along x, section y axis (0, 1, 0): bending about z (EIz) deflects along y and shears
    with kGAy; about y (EIy) along z with kGAz; twist L/GJ."""
    L, EA, GJ, EIy, EIz, kGAy, kGAz = 0.4, 1e6, 3.0, 2.0, 5.0, 40.0, 70.0
    for n in (1, 4):
        m = spacar.Model()
        for k in range(1, n + 1):
            m.beam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2, 0.0, 1.0, 0.0)
            m.x(2 * k + 1, k * L / n, 0.0, 0.0)
            m.rlse(k)
            m.estiff(k, EA, GJ, EIy, EIz, kGAy, kGAz)
        m.fix(1)
        m.fix(2)
        for node in range(3, 2 * n + 3):
            m.dynx(node)
        C = spacar.compliance(m, 2 * n + 1, 2 * n + 2)
        expected = np.zeros((6, 6))
        expected[0, 0] = L / EA
        expected[1, 1], expected[5, 5], expected[1, 5] = L**3 / (3 * EIz) + L / kGAy, L / EIz, L**2 / (2 * EIz)
        expected[2, 2], expected[4, 4], expected[2, 4] = L**3 / (3 * EIy) + L / kGAz, L / EIy, -L**2 / (2 * EIy)
        expected[5, 1], expected[4, 2] = expected[1, 5], expected[2, 4]
        expected[3, 3] = L / GJ
        np.testing.assert_allclose(C, expected, rtol=1e-10, atol=1e-12 * np.abs(expected).max())


def test_a_short_leaf_spring_guide_follows_timoshenko():
    """A parallel guide of two short steel leaves (5 mm long, 2 mm thick: L/h = 2.5, where shear
    takes 17 % of the compliance): the drive stiffness with the section's shear stiffness (Cowper's
    k, section.apply(shear=True)) against two clamped-guided Timoshenko leaves, and 24 EI/L³
    without it."""
    from spacar import section

    L, D = 0.005, 0.03
    leaf = section.rectangle(b=0.01, h=0.002, material=section.STEEL)
    EA, EI, kGA = leaf.plbeam_estiff(shear=True)
    assert kGA == pytest.approx(leaf.shear_coefficient() * section.STEEL.G * leaf.A)
    assert leaf.shear_coefficient() == pytest.approx(10 * 1.3 / (12 + 3.3))

    def guide(shear):
        m = leaf_guide(L, D, n=4)
        for e in range(1, 9):  # axially rigid leaves (EA × 1e6): the stage does not tilt, as the closed form has it
            m.estiff(e, 1e6 * EA, EI, *([kGA] if shear else []))
        return spacar.support_stiffness(m, 9, [1])[0, 0]

    # (1e-7: the stage's remaining tilt, 3e-3 of the stiffness with the leaves' real EA)
    np.testing.assert_allclose(guide(True), 2.0 / (L**3 / (12 * EI) + L / kGA), rtol=1e-7)
    np.testing.assert_allclose(guide(False), 24 * EI / L**3, rtol=1e-7)
    m = leaf_guide(L, D, n=4)
    leaf.apply(m, 1, shear=True)
    assert m.elements[1].estiff == pytest.approx([EA, EI, kGA])
