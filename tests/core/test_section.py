"""Cross-sections and stresses (issue 19, spacar.section): the section properties against values
computed here by hand and against the published Saint-Venant torsion coefficients (Timoshenko &
Goodier, table of k1, k2 for rectangles); the largest stresses of static solutions against
beam theory: a cantilever with a tip load (σ = P (L − x)/W along it, τ = 1.5 P/A), an axial bar
(σ = P/A), a spatial cantilever bent about both axes and twisted.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import spacar
from spacar import section
from spacar.errors import InputError
from support.spatial_models import cantilever as beam_cantilever


def test_material_from_nu_or_g():
    m = section.Material(200e9, nu=0.25, rho=8000.0)
    assert m.G == pytest.approx(80e9)
    assert section.Material(200e9, G=80e9).nu == pytest.approx(0.25)
    assert section.STEEL.E == 210e9 and section.STEEL.rho == 7850.0
    assert section.STEEL.G == pytest.approx(210e9 / 2.6)
    with pytest.raises(InputError, match="either"):
        section.Material(1.0)
    with pytest.raises(InputError, match="either"):
        section.Material(1.0, nu=0.3, G=1.0)
    with pytest.raises(InputError, match="nu"):
        section.Material(1.0, nu=0.6)
    with pytest.raises(InputError, match="E must"):
        section.Material(-1.0, nu=0.3)


def test_rectangle_leaf_spring():
    b, h = 0.02, 0.001  # a 20 mm wide, 1 mm thick leaf
    s = section.rectangle(b, h, section.STEEL)
    assert s.A == pytest.approx(2e-5)
    assert s.Iz == pytest.approx(0.02 * 1e-9 / 12)
    assert s.Iy == pytest.approx(0.001 * 8e-6 / 12)
    assert s.Wz == pytest.approx(0.02 * 1e-6 / 6)
    assert s.Wy == pytest.approx(0.001 * 4e-4 / 6)
    # Thin strip: J = (b h³/3)(1 − 0.630 h/b) up to (h/b)⁵ terms; τ = T h / J.
    assert s.J == pytest.approx(b * h**3 / 3 * (1 - 0.63025 * h / b), rel=1e-5)
    assert s.Wt == pytest.approx(s.J / h, rel=1e-9)
    EA, EI = s.plbeam_estiff()
    assert EA == pytest.approx(210e9 * 2e-5) and EI == pytest.approx(210e9 * 0.02e-9 / 12)
    EA, GJ, EIy, EIz = s.beam_estiff()
    assert GJ == pytest.approx(210e9 / 2.6 * s.J) and EIy == pytest.approx(210e9 * s.Iy)
    assert EIz == pytest.approx(EI)
    assert s.emass() == pytest.approx((7850 * 2e-5,))
    assert s.emass(rotary=True) == pytest.approx((7850 * 2e-5, 7850 * (s.Iy + s.Iz), 7850 * s.Iy, 7850 * s.Iz))


@pytest.mark.parametrize("ratio, k1, k2", [(1.0, 0.1406, 0.208), (2.0, 0.229, 0.246), (4.0, 0.281, 0.282),
                                           (10.0, 0.312, 0.312)])
def test_rectangle_torsion_coefficients(ratio, k1, k2):
    # J = k1 a c³, τmax = T / (k2 a c²) for an a × c rectangle (a ≥ c), tabulated to 3 digits.
    c = 0.01
    for s in (section.rectangle(ratio * c, c), section.rectangle(c, ratio * c)):  # either orientation
        assert s.J / (ratio * c * c**3) == pytest.approx(k1, abs=6e-4)
        assert s.Wt / (ratio * c * c**2) == pytest.approx(k2, abs=6e-4)


def test_circle_and_tube():
    d = 0.01
    s = section.circle(d, section.ALUMINIUM)
    assert s.A == pytest.approx(math.pi * 1e-4 / 4)
    assert s.Iy == s.Iz == pytest.approx(math.pi * 1e-8 / 64)
    assert s.J == pytest.approx(math.pi * 1e-8 / 32)
    assert s.Wz == pytest.approx(math.pi * 1e-6 / 32) and s.Wt == pytest.approx(math.pi * 1e-6 / 16)
    assert s.shear_factor == pytest.approx(4 / 3)
    solid = section.tube(d, d / 2)
    for name in ("A", "Iy", "Iz", "J", "Wy", "Wz", "Wt", "shear_factor"):
        assert getattr(solid, name) == pytest.approx(getattr(s, name), rel=1e-12)
    t = section.tube(0.1, 0.001)
    di = 0.098
    assert t.Iz == pytest.approx(math.pi * (0.1**4 - di**4) / 64)
    assert t.Wt == pytest.approx(math.pi * (0.1**4 - di**4) / 32 / 0.05)
    assert t.shear_factor == pytest.approx(2.0, rel=0.01)  # thin wall: τ = 2V/A
    with pytest.raises(InputError, match="exceeds"):
        section.tube(0.01, 0.006)
    with pytest.raises(InputError, match="no material"):
        section.circle(d).plbeam_estiff()
    with pytest.raises(InputError, match="positive"):
        section.rectangle(0.0, 1.0)


def test_apply_sets_estiff_and_emass_by_element_type():
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.pltruss(2, 3, 5)
    m.x(3, 1.0, 0.0)
    m.x(5, 1.0, 1.0)
    s = section.circle(0.01, section.STEEL)
    assert s.apply(m) is m
    el = m.elements
    np.testing.assert_allclose(el[1].estiff, s.plbeam_estiff())
    np.testing.assert_allclose(el[2].estiff, s.truss_estiff())
    np.testing.assert_allclose(el[1].emass, [7850 * s.A])
    spatial = beam_cantilever(2)
    section.rectangle(0.02, 0.01, section.Material(1e9, nu=0.3)).apply(spatial, 2)  # no density: no EMASS change
    assert spatial.elements[2].estiff[3] == pytest.approx(1e9 * 0.02 * 1e-6 / 12)
    assert list(spatial.elements[2].emass) == list(spatial.elements[1].emass)
    s.apply(spatial, 1)  # a BEAM: the rotary inertia by default (issue 39)
    np.testing.assert_allclose(spatial.elements[1].emass, s.emass(rotary=True))
    s.apply(spatial, 1, rotary=False)
    np.testing.assert_allclose(spatial.elements[1].emass, s.emass())
    with pytest.raises(InputError, match="not defined"):
        s.apply(m, 9)


# ------------------------------------------------------------------------------------------------
# stresses of solutions
# ------------------------------------------------------------------------------------------------

def plbeam_cantilever(n, L, sec, force):
    """n PLBEAMs along x, clamped at nodes 1, 2, the section's stiffness, all deformations DYNE."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k * L / n, 0.0)
        m.dyne(k, 1, 2, 3)
    sec.apply(m)
    m.fix(1)
    m.fix(2)
    m.force(2 * n + 1, *force)
    return m


def test_cantilever_tip_load_bending_and_shear_stress():
    n, L, P = 5, 0.1, 0.01  # small: linear to ~1e-7
    sec = section.rectangle(0.02, 0.002, section.STEEL)
    res = spacar.static(plbeam_cantilever(n, L, sec, (0.0, P)), steps=1)
    s = section.stresses(res, sec)
    assert s.elements == [1, 2, 3, 4, 5]
    # The largest bending moment of element k is at its root end, x = (k − 1) L/n.
    root = np.arange(n) * L / n
    np.testing.assert_allclose(s.normal[-1], P * (L - root) / sec.Wz, rtol=1e-5)
    np.testing.assert_allclose(s.shear[-1], 1.5 * P / sec.A, rtol=1e-5)
    value, element, _ = s.max()["normal"]
    assert element == 1 and value == pytest.approx(P * L / sec.Wz, rel=1e-5)
    normal, shear = s.element(3)
    assert normal[-1] == s.normal[-1, 2] and shear[-1] == s.shear[-1, 2]
    # The same from a dict naming one element only.
    only = section.stresses(res, {2: sec})
    assert only.elements == [2] and only.normal[-1, 0] == s.normal[-1, 1]


def test_axial_bar_stress():
    sec = section.circle(0.004, section.ALUMINIUM)
    P = 50.0
    res = spacar.static(plbeam_cantilever(3, 0.5, sec, (P, 0.0)), steps=1)
    s = section.stresses(res, sec)
    np.testing.assert_allclose(s.normal[-1], P / sec.A, rtol=1e-9)
    np.testing.assert_allclose(s.shear[-1], 0.0, atol=1e-9 * P / sec.A)


def test_spatial_cantilever_bent_about_both_axes_and_twisted():
    n, L = 4, 1.0
    sec = section.rectangle(0.03, 0.02, section.STEEL)
    m = beam_cantilever(n, L=L)
    for e in range(1, n + 1):
        m.dyne(e, 1)
    sec.apply(m)
    Py, Pz, T = 0.02, -0.03, 0.05  # small: the torque of the loads on the deflection is 1e-6 of T
    m.force(n + 1, 0.0, Py, Pz)
    m.apply("FORCE", 100 + n + 1, 0.0, 2.0 * T, 0.0, 0.0)  # r_λ = 2 E(λ)ᵀ m at λ = (1, 0, 0, 0)
    res = spacar.static(m, steps=1)
    assert res.node(n + 1).x[-1][1] > 0  # bends the way it is pushed
    s = section.stresses(res, sec)
    # The clamped end: |Mz| = Py L about z (the y-bending, h = 0.02 along y), |My| = Pz L.
    assert s.normal[-1, 0] == pytest.approx(abs(Py) * L / sec.Wz + abs(Pz) * L / sec.Wy, rel=1e-4)
    assert s.shear[-1, 0] == pytest.approx(abs(T) / sec.Wt + 1.5 * math.hypot(Py, Pz) / sec.A, rel=1e-4)
    f = s.forces[1]
    assert abs(f["T"][-1]) == pytest.approx(abs(T), rel=1e-4)
    # A round section bends about the resultant axis.
    disc = section.circle(0.02, section.STEEL)
    r = section.stresses(res, disc)
    assert r.normal[-1, 0] == pytest.approx(math.hypot(Py, Pz) * L / disc.Wz, rel=1e-4)


def test_stresses_bad_input():
    sec = section.circle(0.004, section.ALUMINIUM)
    res = spacar.static(plbeam_cantilever(2, 0.5, sec, (1.0, 0.0)), steps=1)
    with pytest.raises(InputError, match="not a beam or truss"):
        section.stresses(res, {7: sec})
    with pytest.raises(InputError, match="Section"):
        section.stresses(res, 3.0)


def test_i_beam_constants_against_the_profile_tables_and_a_fine_grid():
    """An IPE 200 without its fillets (h 200, b 100, tw 5.6, tf 8.5 mm): the warping constant is
    the tables' 12.99e3 cm⁶; A, Iy, Iz from a fine grid of the shape; the open section's
    J = Σ b t³/3; the BEAMW ESTIFF carries E Iw."""
    s = section.i_beam(h=200e-3, b=100e-3, tw=5.6e-3, tf=8.5e-3, material=section.STEEL)
    assert s.Iw == pytest.approx(12.99e3 * 1e-12, rel=1e-3)
    n = 2000                                            # cells of a grid over the bounding box
    y = (np.arange(n) + 0.5) / n * 0.2 - 0.1            # along the web (h)
    z = (np.arange(n) + 0.5) / n * 0.1 - 0.05           # along the flanges (b)
    Y, Z = np.meshgrid(y, z, indexing="ij")
    inside = (np.abs(Y) >= 0.1 - 8.5e-3) | (np.abs(Z) <= 2.8e-3)
    dA = (0.2 / n) * (0.1 / n)
    assert s.A == pytest.approx(inside.sum() * dA, rel=2e-3)
    assert s.Iz == pytest.approx((Y**2 * inside).sum() * dA, rel=2e-3)   # strong: the web's plane
    assert s.Iy == pytest.approx((Z**2 * inside).sum() * dA, rel=5e-3)
    assert s.J == pytest.approx((2 * 0.1 * 8.5e-3**3 + 0.183 * 5.6e-3**3) / 3)
    assert s.beam_estiff(warping=True)[6] == pytest.approx(section.STEEL.E * s.Iw)
    assert s.shear_coefficient() == pytest.approx(0.183 * 5.6e-3 / s.A)
    with pytest.raises(spacar.InputError, match="h > 2 tf"):
        section.i_beam(h=0.01, b=0.1, tw=0.005, tf=0.006)


def centre_line_warping(points, thicknesses):
    """(Iw, shear centre (y, z), largest |ω|) of a thin-walled open section along the chain of its
    centre line (points (y, z), one thickness per segment), by the sectorial coordinate: ω about
    the centroid, made orthogonal (t-weighted) to 1, y and z; the shear centre from the removed
    parts (ω_S = ω_B + (z_S − z_B)(y − y_B) − (y_S − y_B)(z − z_B) + c). Exact on straight segments."""
    P = np.asarray(points, dtype=float)
    t = np.asarray(thicknesses, dtype=float)
    L = np.linalg.norm(np.diff(P, axis=0), axis=1)

    def inner(f, g):  # ∫ f g t ds for f, g linear on each segment (values at the points)
        return float(np.sum(t * L * (2 * f[:-1] * g[:-1] + f[:-1] * g[1:] + f[1:] * g[:-1] + 2 * f[1:] * g[1:]) / 6))
    one = np.ones(len(P))
    c = np.array([inner(P[:, k], one) for k in (0, 1)]) / inner(one, one)
    r = P - c
    omega = np.concatenate([[0.0], np.cumsum(r[:-1, 0] * np.diff(P[:, 1]) - r[:-1, 1] * np.diff(P[:, 0]))])
    basis = [one, r[:, 0], r[:, 1]]
    G = np.array([[inner(a, b) for b in basis] for a in basis])
    coef = np.linalg.solve(G, [inner(omega, a) for a in basis])
    normal = omega - sum(k * a for k, a in zip(coef, basis))
    return inner(normal, normal), (c[0] + coef[2], c[1] - coef[1]), float(np.abs(normal).max())


def test_channel_constants_against_the_sectorial_coordinate_and_its_rectangles():
    """A channel 200 x 75 mm, web 8.5, flanges 11.5 mm: A, Iz, Iy, the centroid from its three
    rectangles; Iw, the shear centre and the largest sectorial coordinate from the sectorial
    coordinate of the centre lines integrated along the section (not the closed form)."""
    h, b, tw, tf = 0.200, 0.075, 0.0085, 0.0115
    s = section.channel(h, b, tw, tf, material=section.STEEL)
    hw = h - 2 * tf
    rects = [(b, tf, (h - tf) / 2, b / 2), (b, tf, -(h - tf) / 2, b / 2), (tw, hw, 0.0, tw / 2)]  # (width z, height y, y, z)
    A = sum(w * t for w, t, _, _ in rects)
    zc = sum(w * t * z for w, t, _, z in rects) / A
    assert s.A == pytest.approx(A, rel=1e-14)
    assert s.Iz == pytest.approx(sum(w * t**3 / 12 + w * t * y**2 for w, t, y, _ in rects), rel=1e-12)
    assert s.Iy == pytest.approx(sum(t * w**3 / 12 + w * t * (z - zc) ** 2 for w, t, _, z in rects), rel=1e-12)
    hc, bc = h - tf, b - tw / 2
    Iw, (ys, zs), omega = centre_line_warping([(hc / 2, bc), (hc / 2, 0), (-hc / 2, 0), (-hc / 2, bc)], [tf, tw, tf])
    assert s.Iw == pytest.approx(Iw, rel=1e-12)
    assert ys == pytest.approx(0.0, abs=1e-15)
    assert s.shear_centre == pytest.approx(-zs, rel=1e-12)      # outside, away from the flanges
    assert s.omega == pytest.approx(omega, rel=1e-12)
    assert s.beam_estiff(warping=True)[6] == pytest.approx(section.STEEL.E * s.Iw)
    assert s.shear_areas()[0] == pytest.approx(hw * tw)
    with pytest.raises(spacar.InputError, match="h > 2 tf and tw < b"):
        section.channel(0.2, 0.005, 0.0085, 0.0115)



def test_angle_principal_axes_and_a_cantilever_bent_askew():
    """An unequal angle 100 x 60 x 8 mm: A, the centroid and the second moments in the legs'
    axes from the full rectangle less its cut-out corner (not the code's two legs); the principal
    values are the eigenvalues of that tensor. A cantilever of it, its beam's y along the
    principal axis (principal_y), pushed along the long leg: the tip moves as unsymmetric bending
    gives with the legs' tensor, δ = (L³/3E) S⁻¹ F (S = [[∫y², ∫yz], [∫yz, ∫z²]]), askew to the
    load, to 1e-9 (one beam, shear-rigid, a small load)."""
    h, b, t = 0.100, 0.060, 0.008
    s = section.angle(h, b, t, material=section.STEEL)
    # The bounding rectangle [0, h] × [0, b] less the corner [t, h] × [t, b] (y along h, z along b).
    parts = [(+1, 0.0, h, 0.0, b), (-1, t, h, t, b)]
    A = sum(k * (y1 - y0) * (z1 - z0) for k, y0, y1, z0, z1 in parts)
    yc = sum(k * (y1**2 - y0**2) / 2 * (z1 - z0) for k, y0, y1, z0, z1 in parts) / A
    zc = sum(k * (y1 - y0) * (z1**2 - z0**2) / 2 for k, y0, y1, z0, z1 in parts) / A
    Syy = sum(k * (y1**3 - y0**3) / 3 * (z1 - z0) for k, y0, y1, z0, z1 in parts) - A * yc**2
    Szz = sum(k * (y1 - y0) * (z1**3 - z0**3) / 3 for k, y0, y1, z0, z1 in parts) - A * zc**2
    Syz = sum(k * (y1**2 - y0**2) * (z1**2 - z0**2) / 4 for k, y0, y1, z0, z1 in parts) - A * yc * zc
    assert s.A == pytest.approx(A, rel=1e-13) and s.centroid == pytest.approx((yc, zc), rel=1e-13)
    S = np.array([[Syy, Syz], [Syz, Szz]])
    assert sorted((s.Iy, s.Iz)) == pytest.approx(np.linalg.eigvalsh(S), rel=1e-12)
    assert s.Iz > s.Iy and Syz < 0            # the legs point away from the centroid: ∫yz < 0
    u = np.array([math.cos(s.principal_angle), math.sin(s.principal_angle)])
    assert S @ u == pytest.approx(s.Iz * u, rel=1e-12)  # the principal y': its spread ∫y'² is Iz
    assert s.beam_estiff()[2:] == pytest.approx((section.STEEL.E * s.Iy, section.STEEL.E * s.Iz))
    # The largest normal stress under My = Mz = 1 N·m: at one corner (principal coordinates), less
    # than the two moduli's (different corners) summed.
    corners = np.array([(0, 0), (h, 0), (h, t), (t, t), (t, b), (0, b)]) - (yc, zc)
    yp, zp = corners @ u, corners @ np.array([-u[1], u[0]])
    peak = max(abs(z) / s.Iy + abs(y) / s.Iz for y, z in zip(yp, zp))
    assert s.normal_stress(0.0, 1.0, 1.0) == pytest.approx(peak, rel=1e-12)
    assert peak < 1 / s.Wy + 1 / s.Wz

    L, F = 1.0, 1e-3
    m = spacar.Model()
    m.beam(1, 1, 101, 2, 102, *s.principal_y((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)))
    m.x(1, 0.0, 0.0, 0.0)
    m.x(2, L, 0.0, 0.0)
    m.fix(1)
    m.fix(101)
    m.dyne(1, 2, 3, 4, 5, 6)
    s.apply(m, 1)
    m.force(2, 0.0, F, 0.0)
    m.epskin(1e-13)
    res = spacar.static(m)
    tip = np.array([res.coordinate(2, i)[-1] for i in (1, 2, 3)])
    expected = L**3 / (3 * section.STEEL.E) * np.linalg.solve(S, [F, 0.0])
    assert tip[1:] == pytest.approx(expected, rel=1e-9, abs=1e-9 * np.abs(expected).max())
    assert abs(expected[1]) > 0.3 * abs(expected[0])  # askew: the tip leaves the load's plane
    with pytest.raises(InputError, match="t < h and t < b"):
        section.angle(0.05, 0.005, 0.008)
    with pytest.raises(InputError, match="along the beam's axis"):
        s.principal_y((1.0, 0.0, 0.0), (2.0, 0.0, 0.0))
