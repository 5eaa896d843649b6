"""spacar.light (issue 39): SPACAR Light's model, given as spacarlight.m takes it, gives the closed
forms of flexure design and the same answers as the model built with spacar.flexure: the 3-D
parallel leaf-spring guide's drive stiffness, support stiffness, eigenfrequency and buckling load,
the cross-spring pivot's stiffness (Wittrick: 2EI/L for leaves crossing at their middles) and its
load dependence (Haringx: K = 2EI/L − P L/(6√2) to first order, equal to the builder's pivot), a
Timoshenko cantilever's compliance P L³/3EI + P L/kGA with one beam, moments fixed in global
axes (the clamp's reaction is −M at every step), load steps and prescribed displacements, the
automatic release of a closed loop and the same results with the releases given; results shaped
as spacarlight.m's (1-based steps and nodes, its field names); bad input refused by name."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import flexure, section
from spacar import light, light_model

L, D, W, T = 0.05, 0.03, 0.02, 0.5e-3              # leaves 50 mm long, 30 mm apart, 20 x 0.5 mm
STEEL = section.STEEL
LEAF = section.rectangle(b=W, h=T, material=STEEL)  # the builder's: h, the thickness, along its y axis
EI = STEEL.E * W * T**3 / 12
FLEX = [1, 2, 3, 4, 5, 6]


def leaf_set(elems, nbeams=8, **extra):
    return dict(elems=elems, emod=STEEL.E, smod=STEEL.G, dens=STEEL.rho, cshape="rect", dim=[W, T], orien=[0, 0, 1],
                nbeams=nbeams, flex=FLEX, **extra)


def guide_input(load=None, mass=0.5, **opt):
    """The guide as SPACAR Light writes it: leaves 1–3 and 2–4 along y, the stage the rigid
    element 3–4; node 4 (the stage's corner over leaf 2) carries the mass and the load."""
    nodes = [[0, 0, 0], [D, 0, 0], [0, L, 0], [D, L, 0]]
    elements = [[1, 3], [2, 4], [3, 4]]
    stage = dict(mass=mass, **(load or {}))
    nprops = [dict(fix=True), dict(fix=True), None, stage]
    eprops = [leaf_set([1, 2]), dict(elems=[3])]
    return nodes, elements, nprops, eprops, opt


def builder_guide(force=None):
    """The same guide with spacar.flexure, the stage's reference point at node 4's place, the
    leaves' shear stiffness as spacar.light gives it."""
    fx = flexure.Flexure(spatial=True)
    stage = fx.body(at=(D, L, 0.0), mass=0.5)
    for x0 in (0.0, D):
        fx.leaf_spring(fx.ground, stage, (x0, 0.0, 0.0), (x0, L, 0.0), LEAF, n=8, thickness=(1.0, 0.0, 0.0))
    m = fx.model()
    for leaf in fx.flexures:
        LEAF.apply(m, *leaf.elements, shear=True)
    if force is not None:
        m.force(stage.node, *force)
    return m, stage


def test_guide_equals_the_flexure_builder_and_the_closed_forms():
    out = light(*guide_input(load=dict(force=[0, -1.0, 0]), calcbuck=True, loadsteps=2))
    m, stage = builder_guide()
    C = out.step(1).node(4).CMglob
    Cb = spacar.compliance(m, stage.node, rotation=stage.rotation_node)
    assert C == pytest.approx(Cb, rel=1e-8, abs=1e-8 * np.abs(Cb).max())
    k = 24 * EI / L**3
    assert 1 / C[0, 0] == pytest.approx(k, rel=1e-3)                     # drive: 24EI/L³ (axial, shear: 6e-4)
    assert 1 / C[1, 1] == pytest.approx(STEEL.E * W * T / L, rel=1e-4)  # at the corner: EA/L (the stage tilts)
    f1 = out.step(1).freq[0]
    assert f1 == pytest.approx(spacar.linearize(m).eigenfrequencies(1)[0], rel=1e-8)
    assert f1 == pytest.approx(np.sqrt(k / 0.5) / (2 * np.pi), rel=5e-3)  # (the leaves' mass: 3e-3)
    # Buckling of the step's load (1 N down on the stage): the builder's guide under the same load,
    # and the sway buckling of two clamped-guided leaves, 2π²EI/L², to the mesh's accuracy.
    mb, _ = builder_guide(force=(0.0, -1.0, 0.0))
    spacar.static(mb)
    buck = out.step(2).buck[0]
    assert buck == pytest.approx(abs(spacar.linearize(mb).buckling_factors()[0]), rel=1e-6)
    assert buck == pytest.approx(2 * np.pi**2 * EI / L**2, rel=5e-3)


def test_the_loop_is_released_automatically_and_the_given_releases_give_the_same():
    out = light(*guide_input())
    released = [d for r in out.rls for d in r["def"]]
    assert len(released) == 6                                            # one closed loop in space
    nodes, elements, nprops, eprops, opt = guide_input()
    again = light(nodes, elements, nprops, eprops, out.rls, opt)         # the 1.x call: rls before opt
    assert again.step(1).node(4).CMglob == pytest.approx(out.step(1).node(4).CMglob, rel=1e-9)
    again = light(nodes, elements, nprops, eprops, dict(rls=out.rls))    # 1.38: opt.rls
    assert again.rls == out.rls
    m = light_model(*guide_input())
    assert sum(c.name == "released" for el in m.elements.values() for c in el.cls) == 6


def test_cross_spring_pivot_stiffness():
    """Leaves at ±45° crossing at their middles (Wittrick, Haringx): K = 2EI/L for the rigid body
    joining their upper ends."""
    d1, d2 = np.array([1.0, 1.0, 0.0]) / np.sqrt(2), np.array([-1.0, 1.0, 0.0]) / np.sqrt(2)
    nodes = [-L / 2 * d1, -L / 2 * d2, L / 2 * d1, L / 2 * d2]
    out = light(nodes, [[1, 3], [2, 4], [3, 4]], [dict(fix=True), dict(fix=True)],
                [leaf_set([1, 2], nbeams=8), dict(elems=3)])
    C = out.step(1).node(3).CMglob
    assert 1 / C[5, 5] == pytest.approx(2 * EI / L, rel=1e-3)           # (shear and axial: 3e-4)
    assert C[5, 5] == pytest.approx(out.step(1).node(4).CMglob[5, 5], rel=1e-9)  # one rigid body


def pivot_input(P, nbeams):
    """The cross-spring pivot of the test above, P down shared by the leaves' upper ends (its line
    through the crossing point: no moment at θ = 0)."""
    d1, d2 = np.array([1.0, 1.0, 0.0]) / np.sqrt(2), np.array([-1.0, 1.0, 0.0]) / np.sqrt(2)
    nodes = [-L / 2 * d1, -L / 2 * d2, L / 2 * d1, L / 2 * d2]
    load = dict(force=[0.0, -P / 2, 0.0])
    return (nodes, [[1, 3], [2, 4], [3, 4]], [dict(fix=True), dict(fix=True), load, dict(load)],
            [leaf_set([1, 2], nbeams=nbeams), dict(elems=3)], dict(loadsteps=2))


def builder_pivot(P, nbeams):
    """The same pivot with spacar.flexure: the body's reference point on the axis, midway between
    the leaves' upper ends, where the load acts."""
    d1, d2 = np.array([1.0, 1.0, 0.0]) / np.sqrt(2), np.array([-1.0, 1.0, 0.0]) / np.sqrt(2)
    fx = flexure.Flexure(spatial=True)
    top = fx.body(at=(0.0, L / (2 * np.sqrt(2)), 0.0))
    for d, n in ((d1, d2), (d2, -d1)):        # each leaf thin across itself, in the plane
        fx.leaf_spring(fx.ground, top, tuple(-L / 2 * d), tuple(L / 2 * d), LEAF, n=nbeams, thickness=tuple(n))
    m = fx.model()
    for leaf in fx.flexures:
        LEAF.apply(m, *leaf.elements, shear=True)
    m.force(top.node, 0.0, -P, 0.0)
    return m, top


def test_the_loaded_pivot_s_stiffness_is_haringx_s_and_the_builder_s():
    """A cross-spring pivot carrying a load P along its axis stiffens or softens with it (cf.
    Haringx 1949; the first-order term is derived here, not taken from his exact result). To first
    order in P, for leaves crossing at their middles at 90°: each leaf
    (axial force N = −P/√2) bends into an arc as the top turns by θ about the crossing point, its
    geometric stiffness adding N·(−L/4 + L/6)·θ² to the energy (the chord's shortening by the
    turn, the arc's own by ½∫w′²), and the load's lever lowers it by P·h·θ²/2 with h = L/(2√2) the
    height of its point of action: K(P) = 2EI/L − P·L/(6√2). The slope dK/dP of spacar.light's
    pivot, by central differences at P = ±0.1 N and Richardson's extrapolation from 16 and 32 beams
    per leaf (it converges as h²), equals it to 1e-3; the loaded stiffness equals the builder's."""
    def stiffness(P, nbeams):
        return 1.0 / light(*pivot_input(P, nbeams)).step(2).node(3).CMglob[5, 5]

    slopes = [(stiffness(0.1, n) - stiffness(-0.1, n)) / 0.2 for n in (16, 32)]
    slope = slopes[1] + (slopes[1] - slopes[0]) / 3
    assert slope == pytest.approx(-L / (6 * np.sqrt(2)), rel=1e-3)
    P = 2.0
    m, top = builder_pivot(P, 16)
    spacar.static(m, steps=2)
    Cb = spacar.compliance(m, top.node, rotation=top.rotation_node)
    assert 1.0 / Cb[5, 5] == pytest.approx(stiffness(P, 16), rel=1e-8)
    assert 1.0 / Cb[5, 5] == pytest.approx(2 * EI / L - P * L / (6 * np.sqrt(2)), rel=2e-4)   # P², mesh


def test_timoshenko_cantilever_with_one_beam():
    length = 0.02
    out = light([[0, 0, 0], [length, 0, 0]], [[1, 2]], [dict(fix=True)], [leaf_set([1], nbeams=1)])
    leaf = section.rectangle(b=T, h=W, material=STEEL)                  # spacar.light's: the width along y
    kGA = leaf.shear_coefficient() * STEEL.G * leaf.A
    C = out.step(1).node(2).CMglob
    assert C[1, 1] == pytest.approx(length**3 / (3 * EI) + length / kGA, rel=1e-10)                  # across the leaf
    assert C[2, 2] == pytest.approx(length**3 / (3 * STEEL.E * leaf.Iz) + length / kGA, rel=1e-10)  # along its width


def test_moments_are_fixed_in_space_and_loads_grow_in_steps():
    """A cantilever along x under a tip moment about a skew axis, half of it from the start: the
    clamp's reaction moment is the applied moment reversed at every step (a dead load); about z
    alone the tip turns by M L / EI."""
    M0, M = np.array([0.0, 0.002, 0.01]), np.array([0.004, -0.004, 0.01])
    out = light([[0, 0, 0], [L, 0, 0]], [[1, 2]], [dict(fix=True), dict(moment_initial=M0, moment=M)],
                [leaf_set([1], nbeams=16)], dict(loadsteps=5))
    assert len(out.step) == 5
    for k, step in enumerate(out.step):
        assert step.load == pytest.approx(k / 4)
        assert step.node(1).Mreac == pytest.approx(-(M0 + k / 4 * M), abs=1e-12)
    assert out.node(1).Mreac.shape == (3, 5)                             # steps along the last axis
    Mz = 0.01
    out = light([[0, 0, 0], [L, 0, 0]], [[1, 2]], [dict(fix=True), dict(moment=[0, 0, Mz])],
                [leaf_set([1], nbeams=16)], dict(loadsteps=3))
    angle, *axis = out.step(3).node(2).r_axang                         # about z, the width: the leaf's way
    assert angle == pytest.approx(Mz * L / EI, rel=1e-6) and axis == pytest.approx([0, 0, 1], abs=1e-9)
    assert out.step(3).node(2).r_eulzyx == pytest.approx([angle, 0, 0], abs=1e-12)


def test_prescribed_displacement_and_the_drive_force():
    d = 1e-5
    nodes, elements, nprops, eprops, opt = guide_input(load=dict(displ_x=d))
    out = light(nodes, elements, nprops, eprops, dict(loadsteps=3))
    C = light(*guide_input()).step(1).node(4).CMglob                     # the stage free
    for k, step in enumerate(out.step):
        assert step.node(4).p[0] == pytest.approx(D + d * k / 2, abs=1e-15)
        # the drive pushes with the guide's stiffness at the corner, 1/C[0, 0] (small d: linear)
        assert step.node(4).Freac[0] == pytest.approx(d * k / 2 / C[0, 0], rel=1e-4, abs=1e-12)
    assert out.step(3).node(1).Freac[0] + out.step(3).node(2).Freac[0] == pytest.approx(
        -out.step(3).node(4).Freac[0], rel=1e-9)


@pytest.mark.parametrize("rotation", [dict(rot_z=0.01), dict(rot=[0.01, 0, 0, 2.0]), dict(rot_initial_z=0.01)])
def test_prescribed_rotation_bends_the_leaf_into_an_arc(rotation):
    """The tip of a leaf along x turned about z (the width) by θ, its position free: a constant
    bending moment EI θ / L, the tip's reaction moment, the clamp's its reverse."""
    out = light([[0, 0, 0], [L, 0, 0]], [[1, 2]], [dict(fix=True), rotation], [leaf_set([1], nbeams=8)],
                dict(loadsteps=2))
    tip = out.step(len(out.step)).node(2)
    assert tip.r_axang == pytest.approx([0.01, 0, 0, 1], abs=1e-12)
    assert tip.Mreac == pytest.approx([0, 0, EI * 0.01 / L], rel=1e-4, abs=1e-12)
    assert out.step(len(out.step)).node(1).Mreac == pytest.approx(-tip.Mreac, rel=1e-9, abs=1e-12)


def test_rotations_move_the_euler_parameters_as_spacarlight_writes_them():
    """rot_initial_x then rot_x: INPUTX of λ1 = sin(a/2), DELINPX of sin(b/2), linear in the load."""
    a, b = 0.004, 0.01
    out = light([[0, 0, 0], [L, 0, 0]], [[1, 2]], [dict(fix=True), dict(rot_initial_x=a, rot_x=b)],
                [leaf_set([1], nbeams=4)], dict(loadsteps=3))
    for k, step in enumerate(out.step):
        assert step.node(2).r_quat[1] == pytest.approx(np.sin(a / 2) + k / 2 * np.sin(b / 2), rel=1e-12)


def test_a_column_driven_past_buckling_is_reported_unstable():
    """A clamped leaf shortened by three times its critical shortening π² t²/(12 L) in one step:
    the step is cut back to the critical point and the instability reported in out.warnings."""
    critical = np.pi**2 * T**2 / 12 / L
    out = light([[0, 0, 0], [L, 0, 0]], [[1, 2]], [dict(fix=True), dict(fix_orien=True, displ_x=-3 * critical)],
                [leaf_set([1], nbeams=8)], dict(loadsteps=2, calccompl=False))
    assert out.step(2).results.stats["indefinite_at"] == pytest.approx(1 / 3, rel=2e-2)  # (the cuts' resolution)
    assert any("unstable" in w for w in out.warnings)


def test_light_model_carries_the_full_loads():
    args = guide_input(load=dict(force=[1e-3, -1.0, 0], moment_initial=[0, 0, 1e-4]))
    res = spacar.static(light_model(*args))
    out = light(*args)
    assert res.node(10).x[-1] == pytest.approx(out.step(10).node(4).p, rel=1e-9)


def test_a_rigid_model_has_no_compliance_and_says_so():
    out = light([[0, 0, 0], [L, 0, 0]], [[1, 2]], [dict(fix=True), dict(force=[0, 1, 0])],
                [dict(elems=[1], dens=STEEL.rho, cshape="rect", dim=[W, T])])
    assert out.ndof == 0 and "no degrees of freedom" in out.warnings[0]
    assert not out.step(10).node(2).CMglob.any() and out.step(10).node(1).Freac == pytest.approx([0, -1, 0])
    assert out.node(2).spa_nrs == [4, 5] and out.element(1).Ri == pytest.approx(np.eye(3))  # orien: y, the default


def test_support_stiffness_drops_along_the_stroke():
    """The stroke held at the middle of the stage (displ_x there) and the support stiffness at that
    point: Awtar, Slocum and Sevincer's 2 / (L/EA + L u²/(700 EI)) to the size of its next term
    (tests/core/test_flexure_guide.py), falling to 40 % at u = 4.7 mm."""
    u = 0.0047
    nodes = [[0, 0, 0], [D, 0, 0], [0, L, 0], [D, L, 0], [D / 2, L, 0]]
    nprops = [dict(fix=True), dict(fix=True), None, None, dict(displ_x=u)]
    out = light(nodes, [[1, 3], [2, 4], [3, 5], [5, 4]], nprops, [leaf_set([1, 2], nbeams=16), dict(elems=[3, 4])],
                dict(loadsteps=5))
    EA = STEEL.E * W * T
    for step in out.step:
        v = step.node(5).p[0] - D / 2
        assert v == pytest.approx(step.load * u, abs=1e-15)
        K = 1 / step.node(5).CMglob[1, 1]                                # x held by the input
        assert K == pytest.approx(2 / (L / EA + L * v**2 / (700 * EI)), rel=1e-6 + 2e-2 * (v / (0.1 * L)) ** 2)
    assert K < 0.4 * 2 * EA / L


def test_results_read_as_spacarlight_writes_them():
    out = light(*guide_input(load=dict(force=[1e-3, 0, 0]), loadsteps=4))
    assert out.version == "1.38" and len(out.step) == 4
    s = out.step(4)
    assert s is out.step[3] and s.node(4) is s.node[3]
    node = s.node(4)
    assert node.x is node.p and node.rx_quat is node.r_quat and node.rx_axang is node.r_axang
    assert node.p.shape == (3,) and node.r_quat.shape == (4,) and node.CMloc.shape == (6, 6)
    assert out.node(4).p[:, 3] == pytest.approx(node.p) and out.node(4).CMglob.shape == (6, 6, 4)
    assert out.freq.shape[1] == 4 and out.ndof == len(s.results.dof_labels)
    assert out.element(1).spa_nrs == list(range(1, 9)) and out.element(1).L0 == pytest.approx([L / 8] * 8)
    assert s.element(1).e.shape == (8, 6)
    assert out.stressmax.shape == (4,) and out.stressmax[-1] > out.stressmax[0] >= 0
    # the largest von Mises stress of the leaves: at a clamp, from the guide's end moments
    moment = 1e-3 / 2 * L / 2                                            # each leaf: F/2, guided
    assert out.stressmax[-1] == pytest.approx(moment / (W * T**2 / 6), rel=2e-2)
    with pytest.raises(spacar.InputError, match=r"step\(0\): steps are numbered 1 to 4"):
        out.step(0)


def test_state_space_of_the_transfer_option():
    nodes, elements, nprops, eprops, _ = guide_input()
    nprops[3].update(transfer_in=["force_x"], transfer_out=["displ_x", "veloc_x"])
    out = light(nodes, elements, nprops, eprops, dict(transfer=[True, 0.01]))
    ss = out.statespace
    assert ss.input_names == ["force-x n4"] and ss.output_names == ["displ-x n4", "veloc-x n4"]
    A, B, Cm, Dm = ss.A, ss.B, ss.C, ss.D
    gain = Dm - Cm @ np.linalg.solve(A, B)     # the static gain (A's conditioning: the leaves' fast modes)
    assert gain[0, 0] == pytest.approx(out.step(1).node(4).CMglob[0, 0], rel=1e-4)
    assert gain[1, 0] == pytest.approx(0.0, abs=1e-9)


def test_a_massless_model_has_stiffness_but_no_frequencies():
    nodes, elements, nprops, eprops, opt = guide_input(mass=None)
    eprops[0].pop("dens")
    out = light(nodes, elements, nprops, eprops, opt)
    assert out.step(1).freq.size == 0 and "no mass" in out.warnings[0]
    assert 1 / out.step(1).node(4).CMglob[0, 0] == pytest.approx(24 * EI / L**3, rel=1e-3)


@pytest.mark.parametrize("change, match", [
    (lambda a: a[2][0].update(fixed=True), "unknown nprops\\(1\\) field 'fixed'"),
    (lambda a: a[3][0].update(warping="yes"), "eprops\\(1\\).warping must be true or false"),
    (lambda a: a[3][0].update(orien=[0, 1, 0]), "orien .* lies along element 1"),
    (lambda a: a[1].__setitem__(2, [3, 3]), "element 3 joins node 3 to itself"),
    (lambda a: a[1].__setitem__(2, [3, 5]), "element 3 joins nodes \\[3, 5\\]: node numbers run from 1 to 4"),
    (lambda a: a[4].update(customkin=["DYNX 1"]), "opt.customkin is not supported"),
    (lambda a: a[4].update(loadsteps=0), "opt.loadsteps must be a whole number"),
    (lambda a: a[3][0].pop("emod"), "eprops\\(1\\) needs 'emod'"),
    (lambda a: a[2].__setitem__(3, dict(mass=0.5, fix=True, fix_x=True)), "combines fix with"),
    (lambda a: a.__setitem__(2, [None, None, None, dict(mass=0.5)]), "not exactly constrained"),
    (lambda a: a.__setitem__(1, [[1, 3], [2, 4], [3]]), "elements must be an m x 2 array"),
    (lambda a: a[3][0].update(dens="steel"), "eprops\\(1\\).dens must be 1 number"),
    (lambda a: a[3][0].update(elems=[1, 1]), "lists an element twice"),
    (lambda a: a[2][3].update(transfer_in=[["force_y"]]), "transfer_in must be distinct names"),
    (lambda a: a[2][3].update(force=[1, 0, 0], displ_x=1e-4), "fixes, loads or moves the x position at once"),
    (lambda a: a[2][3].update(moment=[0, 0, 1], rot_z=0.1), "loads \\(moment\\) or turns \\(rot\\)"),
    (lambda a: a[2][3].update(rot=[0.1, 0, 0, 0]), "rot must be \\[angle, x, y, z\\] with a nonzero axis"),
    (lambda a: a[4].update(rls=[None, {"deff": [1]}]), "unknown rls\\(2\\) field 'deff'"),
    (lambda a: a[4].update(transfer=[True, "much"]), "opt.transfer\\{2\\}"),
])
def test_bad_input_is_refused_by_name(change, match):
    args = list(guide_input())
    args[4] = dict(args[4])
    change(args)
    with pytest.raises(spacar.InputError, match=match):
        light(*args)
