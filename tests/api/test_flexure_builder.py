"""spacar.flexure (issue 39): flexure mechanisms built from bodies, leaf springs and wires give
the closed forms of flexure design and the same answers as the models written by hand in
tests/core/test_flexure_guide.py and test_cross_spring_pivot.py (whose formulas are derived
there): the parallel leaf-spring guide's drive stiffness 24 EI/L³ and support stiffness 2EA/L,
the same guide in 3-D (BEAMs; sideways 24 EI_wide/L³), the cross-spring pivot's rotational
stiffness (2EI/L)(12α² − 12α + 4), a wire's tip compliance L³/3EI, and masses on the bodies."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import flexure, section

from support.flexures import B, D, L, N, STAGE, T, leaf_guide, pivot, stiffness
LEAF = section.rectangle(b=B, h=T, material=section.STEEL)
EA, EI = LEAF.plbeam_estiff()
EI_WIDE = section.STEEL.E * LEAF.Iy


def guide(spatial=False, nonlinear=False, stage_mass=0.0, inertia=None, leaf=LEAF):
    fx = flexure.Flexure(spatial=spatial, nonlinear=nonlinear)
    at = (D / 2, L, 0.0) if spatial else (D / 2, L)
    stage = fx.body(at=at, mass=stage_mass, inertia=inertia, name="stage")
    for x0 in (0.0, D):
        a, b = ((x0, 0.0, 0.0), (x0, L, 0.0)) if spatial else ((x0, 0.0), (x0, L))
        fx.leaf_spring(fx.ground, stage, a, b, leaf, n=N, **({"thickness": (1.0, 0.0, 0.0)} if spatial else {}))
    return fx, stage


def test_planar_guide_drive_and_support_stiffness():
    fx, stage = guide()
    m = fx.model()
    C = spacar.compliance(m, stage.node, rotation=stage.rotation_node)
    assert 1 / C[0, 0] == pytest.approx(24 * EI / L**3, rel=5e-4)   # (the leaves' axial compliance: 3e-4)
    assert 1 / C[1, 1] == pytest.approx(2 * EA / L, rel=1e-9)       # at the middle: the leaves as bars
    # The same guide written by hand (the stage a rigid beam between the leaves' tops).
    hand, _ = leaf_guide()
    assert 1 / C[0, 0] == pytest.approx(1 / spacar.compliance(hand, STAGE)[0, 0], rel=1e-10)
    # Each leaf: n elements, RLSE with the section's ESTIFF; its inner nodes DYNX.
    leaf1 = fx.flexures[0]
    assert len(leaf1.elements) == N and len(leaf1.nodes) == N + 1
    el = m.elements[leaf1.elements[0]]
    assert el.type_name == "PLBEAM" and tuple(el.estiff) == pytest.approx(LEAF.plbeam_estiff())


def test_spatial_guide_equals_the_planar_one_and_bends_sideways_on_the_wide_axis():
    fx, stage = guide(spatial=True)
    m = fx.model()
    C = spacar.compliance(m, stage.node, rotation=stage.rotation_node)   # (x, y, z, rotation vector)
    planar, pstage = guide()
    Cp = spacar.compliance(planar.model(), pstage.node, rotation=pstage.rotation_node)
    assert C[0, 0] == pytest.approx(Cp[0, 0], rel=1e-9)      # in the leaves' plane: the planar guide
    assert C[1, 1] == pytest.approx(Cp[1, 1], rel=1e-9)
    # Sideways the stage tilts about x freely: two cantilevers bending about the wide axis.
    assert 1 / C[2, 2] == pytest.approx(2 * 3 * EI_WIDE / L**3, rel=1e-9)
    assert m.elements[fx.flexures[0].elements[0]].type_name == "BEAM"


@pytest.mark.parametrize("alpha", [0.5, 0.3])
def test_cross_spring_pivot(alpha):
    """Leaves at ±45° crossing at the origin, a = αL from their upper ends on the body."""
    fx = flexure.Flexure()
    body = fx.body(at=(0.0, 0.0))                       # its reference point at the crossing
    for d in (np.array([1.0, 1.0]) / np.sqrt(2), np.array([-1.0, 1.0]) / np.sqrt(2)):
        start = -(1 - alpha) * L * d
        fx.leaf_spring(fx.ground, body, start, start + L * d, LEAF, n=N)
    m = fx.model()
    K = 1 / spacar.compliance(m, body.rotation_node)[0, 0]
    assert K == pytest.approx(2 * EI / L * (12 * alpha**2 - 12 * alpha + 4), rel=1e-4)
    assert K == pytest.approx(stiffness(pivot(alpha=alpha)[0]), rel=1e-10)


def test_wire_cantilever_tip_compliance():
    """A round wire from the ground to a body at its end: the body's translation under a tip
    force is L³/3EI and its rotation L²/2EI per unit force (cubic elements: exact)."""
    wire = section.circle(d=0.001, material=section.STEEL)
    EIw = section.STEEL.E * wire.Iz
    fx = flexure.Flexure(spatial=True)
    tip = fx.body(at=(0.0, 0.0, L))
    fx.wire(fx.ground, tip, (0.0, 0.0, 0.0), (0.0, 0.0, L), wire, n=4)
    C = spacar.compliance(fx.model(), tip.node, rotation=tip.rotation_node)
    assert C[0, 0] == pytest.approx(L**3 / (3 * EIw), rel=1e-9)
    assert C[1, 1] == pytest.approx(L**3 / (3 * EIw), rel=1e-9)
    assert abs(C[4, 0]) == pytest.approx(L**2 / (2 * EIw), rel=1e-9)   # rotation about y per Fx


def test_stage_mass_gives_the_guide_its_frequencies():
    """Massless leaves (a material without density) and a stage of mass m and inertia J: the
    modes are those of the stage on its stiffness, the inverse of its compliance in (x, y, β)
    (the leaves statically condensed, exactly); the lowest nearly √(24EI/L³ m)/2π."""
    light = section.rectangle(b=B, h=T, material=section.Material(210e9, nu=0.3, rho=0.0))
    fx, stage = guide(stage_mass=0.5, inertia=1e-4, leaf=light)
    m = fx.model()
    K = np.linalg.inv(spacar.compliance(m, stage.node, rotation=stage.rotation_node))
    expected = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(np.diag([0.5, 0.5, 1e-4]), K)).real)) / (2 * np.pi)
    f = spacar.linearize(m).eigenfrequencies()
    np.testing.assert_allclose(f[:3], expected, rtol=1e-9)
    assert f[0] == pytest.approx(np.sqrt(24 * EI / L**3 / 0.5) / (2 * np.pi), rel=5e-4)
    # Steel leaves add their mass: a lower frequency.
    fx2, _ = guide(stage_mass=0.5, inertia=1e-4)
    assert spacar.linearize(fx2.model()).eigenfrequencies()[0] < f[0]


def test_attachments_and_numbering():
    fx = flexure.Flexure()
    stage = fx.body(at=(D / 2, L))
    one = fx.leaf_spring(fx.ground, stage, (0.0, 0.0), (0.0, L), LEAF, n=2)
    two = fx.leaf_spring(fx.ground, stage, (0.0, 0.0), (D / 2, L), LEAF, n=2)   # the same ground point; the body's own
    assert one.nodes[0] == two.nodes[0]                 # one clamp where two flexures meet the ground
    assert two.nodes[-1] == stage.node                  # at the body's reference point: its nodes
    m = fx.model()
    assert spacar.check(m).ok


@pytest.mark.parametrize("call, match", [
    (lambda fx, s: fx.leaf_spring(fx.ground, s, (0, 0), (0, 0), LEAF), "no length"),
    (lambda fx, s: fx.leaf_spring(fx.ground, fx.ground, (0, 0), (0, 1), LEAF), "two different bodies"),
    (lambda fx, s: fx.leaf_spring(fx.ground, s, (0, 0), (0, 1), "leaf"), "section"),
    (lambda fx, s: fx.leaf_spring(fx.ground, s, (0, 0), (0, 1), LEAF, n=0), "number of elements"),
    (lambda fx, s: fx.leaf_spring(fx.ground, s, (0, 0, 0), (0, 1), LEAF), "point of 2"),
    (lambda fx, s: fx.leaf_spring(fx.ground, object(), (0, 0), (0, 1), LEAF), "body of this flexure"),
    (lambda fx, s: fx.leaf_spring(fx.ground, s, (0, 0), (0, 1), section.rectangle(1, 1)), "no material"),
    (lambda fx, s: fx.body(at=(0, 1), mass=-1.0), "mass"),
    (lambda fx, s: fx.body(at=(0, 1), inertia=(1, 2)), "inertia"),
    (lambda fx, s: fx.model(), "no flexures"),
])
def test_bad_input_is_refused_by_name(call, match):
    fx = flexure.Flexure()
    stage = fx.body(at=(0.0, 1.0))
    with pytest.raises(spacar.InputError, match=match):
        call(fx, stage)


def test_spatial_errors_and_an_unjoined_body():
    fx = flexure.Flexure(spatial=True)
    stage = fx.body(at=(0.0, 1.0, 0.0))
    with pytest.raises(spacar.InputError, match="direction of its thickness"):
        fx.leaf_spring(fx.ground, stage, (0, 0, 0), (0, 1, 0), LEAF)
    with pytest.raises(spacar.InputError, match="along the beam"):
        fx.leaf_spring(fx.ground, stage, (0, 0, 0), (0, 1, 0), LEAF, thickness=(0, 2, 0))
    fx.leaf_spring(fx.ground, stage, (0, 0, 0), (0, 1, 0), LEAF, thickness=(1, 0, 0))
    fx.body(at=(5.0, 5.0, 5.0), name="loose")
    with pytest.raises(spacar.InputError, match="'loose' is joined to nothing"):
        fx.model()


def notch(n, spatial=False, R=0.005, t=0.0005, w=0.01):
    fx = flexure.Flexure(spatial=spatial)
    body = fx.body(at=(0.0, R + 0.01, 0.0) if spatial else (0.0, R + 0.01))
    extra = {"thickness_axis": (1.0, 0.0, 0.0)} if spatial else {}
    origin, up = ((0.0, 0.0, 0.0), (0.0, 1.0, 0.0)) if spatial else ((0.0, 0.0), (0.0, 1.0))
    hinge = fx.notch_hinge(fx.ground, body, origin, up, radius=R, thickness=t, width=w, material=section.STEEL,
                           n=n, **extra)
    return fx, body, hinge


def test_notch_hinge_compliance_is_the_closed_form():
    """A right-circular notch hinge (R = 5 mm, t = 0.5 mm, 10 mm wide) between the ground and a
    body: its rotational compliance under a moment is the midpoint sum of ∫ dx/E I(x) over its
    pieces exactly (cubic beams of constant section), which converges to the integral — Paros and
    Weisbord's exact closed form, computed here by quadrature — to 1e-5 with the default 40
    pieces; their simplified 9π√R / (2 E w t^{5/2}) (for t ≪ R) is 1.3 % off at t/R = 0.1."""
    from scipy.integrate import quad

    R, t, w, E = 0.005, 0.0005, 0.01, section.STEEL.E
    profile = lambda x: t + 2 * (R - np.sqrt(R * R - x * x))  # noqa: E731
    exact = quad(lambda x: 12 / (E * w * profile(x) ** 3), -R, R, points=[0], limit=200, epsrel=1e-13)[0]
    fx, body, hinge = notch(40)
    C = spacar.compliance(fx.model(), body.rotation_node)[0, 0]
    x = -R + (np.arange(40) + 0.5) * (2 * R / 40)
    assert C == pytest.approx(np.sum(2 * R / 40 * 12 / (E * w * profile(x) ** 3)), rel=1e-10)
    assert C == pytest.approx(exact, rel=1e-5)
    assert C == pytest.approx(9 * np.pi * np.sqrt(R) / (2 * E * w * t**2.5), rel=0.015)
    assert len(hinge.elements) == 40 and hinge.kind == "notch hinge"
    coarse = spacar.compliance(notch(20)[0].model(), notch(20)[1].rotation_node)[0, 0]
    assert abs(C / exact - 1) < abs(coarse / exact - 1)                 # converging with the mesh
    # In space, bending across the thin section: the planar hinge's compliance.
    fx3, body3, _ = notch(40, spatial=True)
    C3 = spacar.compliance(fx3.model(), body3.rotation_node)           # rotation vector (x, y, z) per moment
    assert C3[2, 2] == pytest.approx(C, rel=1e-9)
    assert C3[0, 0] < 1e-2 * C                                          # about the thickness axis: the width resists
    with pytest.raises(spacar.InputError, match="thickness_axis"):
        flexure.Flexure(spatial=True).notch_hinge(fx3.ground, body3, (0, 0, 0), (0, 1, 0), radius=R, thickness=t,
                                                  width=w, material=section.STEEL)
    with pytest.raises(spacar.InputError, match="radius must be a positive number"):
        notch(4, R=-1.0)


def test_elliptical_notch_hinge():
    """An elliptical notch (semi-axes 8 mm along the hinge, 3 mm deep): its compliance is the
    quadrature of ∫ dx / E I(x) over its profile t + 2b(1 − √(1 − x²/a²)) to 1e-5; with the depth
    equal to the radius it is the circular hinge exactly; longer and shallower cuts make it more
    compliant than the circle of the same radius."""
    from scipy.integrate import quad

    a, b, t, w, E = 0.008, 0.003, 0.0005, 0.01, section.STEEL.E

    def hinge(depth):
        fx = flexure.Flexure()
        body = fx.body(at=(0.0, a + 0.01))
        fx.notch_hinge(fx.ground, body, (0.0, 0.0), (0.0, 1.0), radius=a, depth=depth, thickness=t, width=w,
                       material=section.STEEL)
        return spacar.compliance(fx.model(), body.rotation_node)[0, 0]

    profile = lambda x: t + 2 * b * (1 - np.sqrt(1 - (x / a) ** 2))  # noqa: E731
    exact = quad(lambda x: 12 / (E * w * profile(x) ** 3), -a, a, points=[0], limit=200, epsrel=1e-13)[0]
    assert hinge(b) == pytest.approx(exact, rel=1e-5)
    assert hinge(a) == pytest.approx(hinge(None), rel=1e-14)
    assert hinge(b) > hinge(a)


def test_column_past_its_buckling_load_is_reported_unstable():
    """A leaf as a clamped-free column (PLBEAMNL, RLSE, every node DYNX, as the builder makes it)
    under 1.05 of its buckling load in 10 load steps: the axial problem is linear, so Newton
    converges in one iteration per step, and the stability verdict must come from a tangent at
    the new load (not the step start's): unstable from λ = 1/1.05 on. Its buckling load is
    π²EI/4L² to 3e-6."""
    def column(P):
        fx = flexure.Flexure(nonlinear=True)
        top = fx.body(at=(0.0, L))
        fx.leaf_spring(fx.ground, top, (0.0, 0.0), (0.0, L), LEAF, n=N)
        m = fx.model()
        m.force(top.node, 0.0, -P)
        return m

    m = column(1.0)
    spacar.static(m, steps=1)
    P_cr = spacar.linearize(m).buckling_factors(k=1)[0]
    assert P_cr == pytest.approx(np.pi**2 * EI / (4 * L**2), rel=3e-6)
    m = column(1.05 * P_cr)
    res = spacar.static(m, steps=10)
    assert res.stats["indefinite_at"] == pytest.approx(1 / 1.05, abs=1e-3)
    assert any("indefinite" in w for w in m.warnings)


def test_ground_points_are_shared_at_any_scale():
    fx = flexure.Flexure()
    stage = fx.body(at=(15.0, 50.0))                   # millimetres
    one = fx.leaf_spring(fx.ground, stage, (0.0, 0.0), (0.0, 50.0), LEAF, n=2)
    fx.body(at=(500.0, 500.0), name="far")             # the model grows
    two = fx.leaf_spring(fx.ground, stage, (0.0, 0.0), (30.0, 50.0), LEAF, n=2)
    assert one.nodes[0] == two.nodes[0]


def test_arc_flexures_follow_the_stroke_with_few_elements():
    """Flexure(arc=True) meshes the leaves with PLBEAMC: at rest the guide of PLBEAM (the same
    tangent), along a 4.7 mm stroke (40 N on the stage) 8 elements give the stage's travel to 22 nm
    of a 256-element PLBEAMNL mesh, where 8 PLBEAMNLs are 2.3 µm off; its support stiffness converges
    no faster (8 elements: within 2e-3 of the fine mesh's, PLBEAMNL within 1e-3)."""
    def stroke(n, **kind):
        fx = flexure.Flexure(**kind)
        stage = fx.body(at=(D / 2, L), name="stage")
        for x0 in (0.0, D):
            fx.leaf_spring(fx.ground, stage, (x0, 0.0), (x0, L), LEAF, n=n)
        m = fx.model()
        C0 = spacar.compliance(m, stage.node, rotation=stage.rotation_node)
        m.force(stage.node, 40.0, 0.0)
        u = spacar.static(m, steps=4).node(stage.node).x[-1][0] - D / 2
        C = spacar.compliance(m, stage.node, rotation=stage.rotation_node)
        held = C[1:, 1:] - np.outer(C[1:, 0], C[0, 1:]) / C[0, 0]   # the stroke held: support stiffness
        return C0, u, 1 / held[0, 0]

    C0, u, k = stroke(8, arc=True)
    fx, stage = guide()
    assert C0 == pytest.approx(spacar.compliance(fx.model(), stage.node, rotation=stage.rotation_node), rel=1e-10)
    _, u_ref, k_ref = stroke(256, nonlinear=True)
    _, u_nl, k_nl = stroke(8, nonlinear=True)
    assert abs(u - u_ref) < 3e-8 and abs(u_nl - u_ref) > 2e-6
    assert k == pytest.approx(k_ref, rel=2e-3) and k_nl == pytest.approx(k_ref, rel=1e-3)
    with pytest.raises(spacar.InputError, match="not with nonlinear=True"):
        flexure.Flexure(arc=True, nonlinear=True)


def test_arc_flexures_in_space_are_beamcs():
    """Flexure(spatial=True, arc=True): the 3-D guide of BEAMCs, at rest the BEAM guide, and
    along the stroke in its plane the planar guide of PLBEAMCs."""
    fx = flexure.Flexure(spatial=True, arc=True)
    stage = fx.body(at=(D / 2, L, 0.0), name="stage")
    for x0 in (0.0, D):
        fx.leaf_spring(fx.ground, stage, (x0, 0.0, 0.0), (x0, L, 0.0), LEAF, n=N, thickness=(1.0, 0.0, 0.0))
    m = fx.model()
    assert m.elements[fx.flexures[0].elements[0]].type_name == "BEAMC"
    beams, beams_stage = guide(spatial=True)
    C = spacar.compliance(m, stage.node, rotation=stage.rotation_node)
    assert C == pytest.approx(spacar.compliance(beams.model(), beams_stage.node, rotation=beams_stage.rotation_node),
                              rel=1e-9, abs=1e-12 * np.abs(C).max())
    # the leaves' mass and rotary inertia as the BEAMs' (the stage massless): the same modes
    assert spacar.linearize(m).M0 == pytest.approx(spacar.linearize(beams.model()).M0, rel=1e-12, abs=1e-15)
    m.force(stage.node, 40.0, 0.0, 0.0)
    planar = flexure.Flexure(arc=True)
    pstage = planar.body(at=(D / 2, L), name="stage")
    for x0 in (0.0, D):
        planar.leaf_spring(planar.ground, pstage, (x0, 0.0), (x0, L), LEAF, n=N)
    pm = planar.model()
    pm.force(pstage.node, 40.0, 0.0)
    u = spacar.static(m, steps=4).node(stage.node).x[-1]
    up = spacar.static(pm, steps=4).node(pstage.node).x[-1]
    assert u[:2] == pytest.approx(up, abs=1e-12) and abs(u[2]) < 1e-15


def test_warping_leaves_are_beamws_held_at_their_clamps():
    """Flexure(spatial=True, warping=True): the 3-D guide of BEAMWs, its leaves held from warping
    at the ground and at the stage; equal to the same guide through spacar.light with warping
    (the stage a rigid element with warping, which holds it too); the drive as the BEAM guide's to
    1e-3 (it hardly twists the leaves), the stage's turn about the leaves' axis (their twist with
    their bending about the wide axis) 3e-4 stiffer."""
    leaf = section.rectangle(b=B, h=T, material=section.STEEL)
    fx = flexure.Flexure(spatial=True, warping=True)
    stage = fx.body(at=(D, L, 0.0), name="stage")
    for x0 in (0.0, D):
        fx.leaf_spring(fx.ground, stage, (x0, 0.0, 0.0), (x0, L, 0.0), leaf, n=N, thickness=(1.0, 0.0, 0.0))
    m = fx.model()
    assert {m.elements[e].type_name for e in fx.flexures[0].elements} == {"BEAMW"}
    for lf in fx.flexures:
        leaf.apply(m, *lf.elements, shear=True)
    C = spacar.compliance(m, stage.node, rotation=stage.rotation_node)
    props = dict(emod=section.STEEL.E, smod=section.STEEL.G, cshape="rect", dim=[B, T], orien=[0, 0, 1], nbeams=N,
                 flex=[1, 2, 3, 4, 5, 6], warping=True)
    out = spacar.light([[0, 0, 0], [D, 0, 0], [0, L, 0], [D, L, 0]], [[1, 3], [2, 4], [3, 4]],
                       [dict(fix=True), dict(fix=True)], [dict(props, elems=[1, 2]), dict(elems=[3], warping=True)])
    assert C == pytest.approx(out.step(1).node(4).CMglob, rel=1e-7, abs=1e-9 * np.abs(C).max())
    beams, beams_stage = guide(spatial=True)
    mb = beams.model()
    for lf in beams.flexures:
        leaf.apply(mb, *lf.elements, shear=True)
    C_beam = spacar.compliance(mb, beams_stage.node, rotation=beams_stage.rotation_node)
    assert C[0, 0] == pytest.approx(C_beam[0, 0], rel=1e-3)
    assert C[4, 4] < (1 - 1e-4) * C_beam[4, 4]
    with pytest.raises(spacar.InputError, match="warping=True meshes the flexures with BEAMW, in space"):
        flexure.Flexure(warping=True)


def test_corner_filleted_hinge():
    """A corner-filleted hinge (a thin section 0.5 mm thick running straight over l, fillets of
    radius 1 mm into the bodies): its rotational compliance is the quadrature of ∫ dx / E I(x)
    over the profile to 1e-4 with 40 pieces, 3e-5 with 80; long, it tends to the straight
    section's 12 l / (E w t³) plus the two fillets; with l = 0 it is the right-circular hinge."""
    from scipy.integrate import quad

    R, t, w, E = 0.001, 0.0005, 0.01, section.STEEL.E

    def compliance(length, n):
        fx = flexure.Flexure()
        body = fx.body(at=(0.0, length / 2 + R + 0.01))
        hinge = fx.notch_hinge(fx.ground, body, (0.0, 0.0), (0.0, 1.0), radius=R, thickness=t, width=w,
                               material=section.STEEL, n=n, length=length)
        return spacar.compliance(fx.model(), body.rotation_node)[0, 0], hinge

    def quadrature(length):
        profile = lambda x: t + 2 * (R - np.sqrt(R * R - (abs(x) - length / 2) ** 2))  # noqa: E731 - the fillet
        fillet = quad(lambda x: 12 / (E * w * profile(x) ** 3), length / 2, length / 2 + R, limit=400, epsrel=1e-14)[0]
        return 2 * fillet + 12 * length / (E * w * t**3)
    for length in (0.005, 0.001):
        exact = quadrature(length)
        assert compliance(length, 40)[0] == pytest.approx(exact, rel=1e-4)
        assert compliance(length, 80)[0] == pytest.approx(exact, rel=3e-5)
    C, hinge = compliance(0.005, 40)
    ends = [np.asarray(p) for p in (hinge.a, hinge.b)]
    assert np.linalg.norm(ends[1] - ends[0]) == pytest.approx(0.005 + 2 * R)
    assert compliance(0.0, 40)[0] == pytest.approx(spacar.compliance(*_circular(R, t, w)), rel=1e-12)
    with pytest.raises(spacar.InputError, match="length must be a non-negative number"):
        compliance(-1.0, 40)


def _circular(R, t, w):
    fx = flexure.Flexure()
    body = fx.body(at=(0.0, R + 0.01))
    fx.notch_hinge(fx.ground, body, (0.0, 0.0), (0.0, 1.0), radius=R, thickness=t, width=w, material=section.STEEL,
                   n=40)
    return fx.model(), body.rotation_node
