"""BEAMW (issue 39, extension): warping torsion after Vlasov. A steel strip 20 x 0.5 mm, 50 mm
long (kL = 10.6, k = √(GJ/EIw)), twisted by an end torque T:

* warping restrained at the clamp, free at the loaded end: θ(L) = (T/GJ)(L − tanh(kL)/k),
  the cubic twist of the elements converging as h⁴ (0.2 % with 4 elements, 2e-4 with 8);
* warping restrained at both ends (the loaded end turns, as clamped into a rigid stage, but does
  not warp): θ(L) = (T/GJ)(L − (2/k) tanh(kL/2));
* warping free everywhere: T L/GJ, as BEAM, to the geometric nonlinearity (ψ² ~ 1e-7);
* its warping inertia ρIw makes the mass of the rates (with a clamped stage the torsion modes).
The section constants are those spacar.section gives a thin rectangle: Iw = b³h³/144."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import section

E, G, W, T, L = 210e9, 80e9, 0.02, 0.0005, 0.05
GJ = G * W * T**3 / 3 * (1 - 0.63 * T / W)
EIW = E * W**3 * T**3 / 144
K = np.sqrt(GJ / EIW)
TORQUE = 1e-3


def strip(n, restrained=(True, False), kind="beamw"):
    """n BEAMWs along x: node 3i+1 its XYZ, 3i+2 its LAMBDA, 3i+3 its warping rate; the root
    clamped, the tip loaded by a torque about x; warping restrained where asked."""
    m = spacar.Model()
    for i in range(n):
        m.beamw(i + 1, 3 * i + 1, 3 * i + 2, 3 * i + 4, 3 * i + 5, 3 * i + 3, 3 * i + 6, 0, 1, 0)
        m.estiff(i + 1, E * W * T, GJ, E * W * T**3 / 12, E * T * W**3 / 12, 0, 0, EIW)
        m.rlse(i + 1)
    for i in range(n + 1):
        m.x(3 * i + 1, L * i / n, 0, 0)
        for j in (1, 2, 3):
            if i > 0 or j == 3:
                m.dynx(3 * i + j)
    m.fix(1)
    m.fix(2)
    for end, node in zip(restrained, (3, 3 * n + 3)):
        if end:
            m.fix(node)
    m.torqueg(3 * n + 2, TORQUE, 0, 0)
    return m


def twist(n, restrained):
    lam = spacar.static(strip(n, restrained), steps=1).node(3 * n + 2).x[-1]
    return 2 * np.arctan2(lam[1], lam[0])


def test_warping_restrained_at_the_clamp():
    exact = TORQUE / GJ * (L - np.tanh(K * L) / K)
    errors = [abs(twist(n, (True, False)) / exact - 1) for n in (4, 8, 16)]
    assert errors[0] < 5e-3 and errors[1] < 3e-4 and errors[2] < 2e-5
    assert errors[0] / errors[1] > 10                      # h⁴
    assert exact < 0.92 * TORQUE * L / GJ                 # the restraint stiffens the strip by 10 %


def test_warping_restrained_at_both_ends():
    exact = TORQUE / GJ * (L - 2 / K * np.tanh(K * L / 2))
    assert twist(16, (True, True)) == pytest.approx(exact, rel=5e-5)


def test_free_warping_is_saint_venant_torsion():
    assert twist(2, (False, False)) == pytest.approx(TORQUE * L / GJ, rel=2e-7)
    assert twist(8, (False, False)) == pytest.approx(TORQUE * L / GJ, rel=2e-7)


def test_warping_inertia_and_the_section_constant():
    leaf = section.rectangle(b=W, h=T, material=section.STEEL)
    assert leaf.Iw == pytest.approx(W**3 * T**3 / 144)
    m = strip(8)
    leaf.apply(m)                                           # EIw and ρIw from the section too
    assert m.elements[1].estiff[6] == pytest.approx(section.STEEL.E * leaf.Iw)
    assert m.elements[1].emass[4] == pytest.approx(section.STEEL.rho * leaf.Iw)
    spacar.static(m)
    f = spacar.linearize(m).eigenfrequencies(4)
    assert np.isfinite(f).all() and f[0] > 0               # every rate of twist carries inertia


def test_spacar_light_models_warping_with_beamw():
    """eprops.warping = true: the strip as SPACAR Light writes it (BEAMWs, the warping node 3i of
    node i fixed at the clamp) twists as Vlasov's strip; without warping, as Saint-Venant's."""
    leaf = section.rectangle(b=T, h=W, material=section.Material(E, G=G))   # spacar.light's: the width along y
    gj, eiw = G * leaf.J, E * leaf.Iw
    k = np.sqrt(gj / eiw)
    props = dict(elems=[1], emod=E, smod=G, cshape="rect", dim=[W, T], orien=[0, 1, 0], nbeams=8,
                 flex=[1, 2, 3, 4, 5, 6])
    nodes, elements = [[0, 0, 0], [L, 0, 0]], [[1, 2]]
    nprops = [dict(fix=True), dict(moment=[TORQUE, 0, 0])]
    out = spacar.light(nodes, elements, nprops, [dict(props, warping=True)], dict(loadsteps=2))
    assert {el.type_name for el in out.model.elements.values()} >= {"BEAMW"}
    assert out.model.nodes[3].cls[0].name == "fixed"                       # the clamp's warping
    assert out.step(2).node(2).r_axang[0] == pytest.approx(TORQUE / gj * (L - np.tanh(k * L) / k), rel=3e-4)
    free = spacar.light(nodes, elements, nprops, [props], dict(loadsteps=2))
    assert free.step(2).node(2).r_axang[0] == pytest.approx(TORQUE * L / gj, rel=1e-6)


def test_torque_and_warping_stress_of_a_restrained_strip_and_its_drawing():
    """Every element carries the whole torque, l0 (σ2 − σ7 + σ8) (Saint-Venant's share falls to
    0.45 next to the clamp); the warping normal stress at the clamp is Vlasov's bimoment
    (T/k) tanh(kL) times ω/Iw, ω = W T/4 (the elements' end curvature of the twist: 2.8 % low
    with 16 elements, 0.7 % with 32); the strip draws."""
    import matplotlib

    matplotlib.use("Agg")
    n = 32
    m = strip(n)
    leaf = section.rectangle(b=W, h=T, material=section.Material(E, G=G))
    res = spacar.static(m, steps=1)
    s = section.stresses(res, {e: leaf for e in range(1, n + 1)})
    for e in range(1, n + 1):
        assert s.forces[e]["T"][-1] == pytest.approx(TORQUE, rel=1e-6)
    bimoment = TORQUE / K * np.tanh(K * L)
    warping_stress = abs(s.forces[1]["warping"][-1, 0]) * E * leaf.omega
    assert warping_stress == pytest.approx(bimoment * leaf.omega / (W**3 * T**3 / 144), rel=1e-2)
    assert s.normal[-1, 0] >= warping_stress
    spacar.draw(res)


def test_spacar_light_warping_with_given_releases_and_round_sections():
    props = dict(elems=[1], emod=E, smod=G, cshape="rect", dim=[W, T], orien=[0, 1, 0], nbeams=4,
                 flex=[1, 2, 3, 4, 5, 6], warping=True)
    nodes, elements = [[0, 0, 0], [L, 0, 0], [L, L, 0]], [[1, 2], [2, 3]]
    nprops = [dict(fix=True), None, dict(fix=True)]                        # a closed frame: releases
    frame = dict(props, elems=[1, 2], orien=[0, 0, 1])
    out = spacar.light(nodes, elements, nprops, [frame], dict(loadsteps=1))
    assert all(d <= 6 for r in out.rls for d in r["def"])
    again = spacar.light(nodes, elements, nprops, [frame], dict(loadsteps=1, rls=out.rls))
    assert again.step(1).node(2).CMglob == pytest.approx(out.step(1).node(2).CMglob, rel=1e-9)
    rod = spacar.light([[0, 0, 0], [L, 0, 0]], [[1, 2]], [dict(fix=True)],
                       [dict(props, cshape="circ", dim=[0.002], orien=[0, 1, 0])])
    assert "does not warp" in rod.warnings[0] and any("no mass" in w for w in rod.warnings[1:])
    assert {el.type_name for el in rod.model.elements.values()} == {"BEAM", "L2MIN1"}


def test_i_beam_shear_areas():
    s = section.i_beam(h=0.2, b=0.2, tw=0.009, tf=0.015, material=section.STEEL)   # about an HE 200 B
    G_ = section.STEEL.G
    assert s.beam_estiff(shear=True)[4:6] == pytest.approx((G_ * 0.17 * 0.009, G_ * 5 / 6 * 2 * 0.2 * 0.015))
    assert s.shear_stress(0.0, 1000.0, 0.0) == pytest.approx(1000.0 / (0.17 * 0.009))
    assert s.shear_stress(0.0, 0.0, 1000.0) == pytest.approx(1.5 * 1000.0 / (2 * 0.2 * 0.015))
