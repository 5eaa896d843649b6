"""Design sensitivities (issue 40): the derivatives of static displacements, eigenfrequencies and
compliances with respect to ESTIFF, EMASS, MASS values and section dimensions, by the direct
method (spacar.sensitivity), against central differences of the whole analysis (the equilibrium
solved again, the modes computed again) to 1e-7 relative, and against closed forms: a
cantilever's tip deflection P L³ / 3EI and first frequency (1.8751²/2π) √(EI / ρA L⁴) scale as
1/EI and √(EI/ρA), so their derivatives summed over the elements are −δ/EI, f/2EI and −f/2ρA; the
parallel leaf-spring guide's drive compliance L³/24EI in the leaves' thickness (∝ t⁻³); a
prestressed column, a large deflection and the UR5 with elastic joints."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import sensitivity, section

L, N, EI, EA, RHOA, P = 1.0, 8, 2.0, 1e6, 1.5, 0.03


def cantilever(load=(0.0, -P), masses=True):
    """A planar cantilever of N PLBEAMs along x, clamped at node 1, loaded at its tip."""
    m = spacar.Model()
    for i in range(N):
        m.plbeam(i + 1, 2 * i + 1, 2 * i + 2, 2 * i + 3, 2 * i + 4)
        m.x(2 * i + 3, L * (i + 1) / N, 0.0)
        m.dyne(i + 1, 1, 2, 3)
        m.estiff(i + 1, EA, EI)
        if masses:
            m.emass(i + 1, RHOA)
    m.x(1, 0.0, 0.0)
    m.fix(1)
    m.fix(2)
    tip = 2 * N + 1
    if load is not None:
        m.force(tip, *load)
    return m, tip


def whole(make, parameter, quantity, rel=1e-3):
    """d quantity(model)/dp by central differences of the whole analysis, the parameter changed in
    a fresh model, extrapolated (Richardson) from the steps h and h/2: error O(h⁴)."""
    kind, number, index = parameter

    def central(step):
        values = {}
        for sign in (1, -1):
            m, _ = make()
            table = m.core.nodes if kind == "MASS" else m.core.elements
            vals = list(getattr(table[number], kind.lower()))
            vals[index - 1] += sign * step
            getattr(m, kind.lower())(number, *vals)
            values[sign] = np.asarray(quantity(m))
        return (values[1] - values[-1]) / (2 * step)
    m, _ = make()
    table = m.core.nodes if kind == "MASS" else m.core.elements
    h = rel * abs(list(getattr(table[number], kind.lower()))[index - 1])
    return (4 * central(h / 2) - central(h)) / 3


def tip_deflection(m, tip):
    res = spacar.static(m)
    return res.node(tip).x[-1]


def lowest_frequencies(m, k=3):
    spacar.static(m)
    return spacar.linearize(m).eigenfrequencies()[:k]


def test_the_tip_deflection_against_the_closed_form_and_differences():
    m, tip = cantilever()
    params = [("ESTIFF", e, 2) for e in range(1, N + 1)] + [("ESTIFF", 3, 1)]
    s = sensitivity.displacements(m, params)
    dy = s.node(tip)[1]
    delta = -P * L**3 / (3 * EI)
    assert s.x[s.coordinate_labels.index((tip, 2))] == pytest.approx(delta, rel=1e-4)   # nearly linear
    # δ ∝ 1/EI: the derivatives over all elements sum to −δ/EI (to the small nonlinearity).
    assert dy[:N].sum() == pytest.approx(P * L**3 / (3 * EI**2), rel=1e-4)
    for j in (0, 5, N):
        reference = whole(lambda: cantilever(), params[j], lambda mm: tip_deflection(mm, tip)[1])
        assert dy[j] == pytest.approx(reference, rel=1e-7)


def test_a_large_deflection_against_differences():
    big = (0.0, -1.2 * EI / L**2)   # P L² / EI = 1.2, a tip rotation of about 0.5 rad: far from linear
    m, tip = cantilever(load=big)
    params = [("ESTIFF", 2, 2), ("ESTIFF", 7, 2)]
    s = sensitivity.displacements(m, params)
    for j, p in enumerate(params):
        reference = whole(lambda: cantilever(load=big), p, lambda mm: tip_deflection(mm, tip))
        assert s.node(tip)[:2, j] == pytest.approx(reference, rel=1e-7, abs=1e-7 * np.abs(reference).max())


def test_the_cantilever_frequencies_scale_as_the_closed_form():
    m, _ = cantilever(load=None)
    params = [("ESTIFF", e, 2) for e in range(1, N + 1)] + [("EMASS", e, 1) for e in range(1, N + 1)]
    s = sensitivity.frequencies(m, params, k=3)
    f1 = 1.8751040687**2 / (2 * np.pi) * np.sqrt(EI / (RHOA * L**4))
    assert s.frequencies[0] == pytest.approx(f1, rel=1e-4)
    # f ∝ √(EI/ρA) for every mode: the sums over the elements are f/2EI and −f/2ρA exactly.
    assert s.df[:, :N].sum(axis=1) == pytest.approx(s.frequencies / (2 * EI), rel=1e-10)
    assert s.df[:, N:].sum(axis=1) == pytest.approx(-s.frequencies / (2 * RHOA), rel=1e-10)
    for j in (0, 3, N + 2):
        reference = whole(lambda: cantilever(load=None), params[j], lowest_frequencies)
        assert s.df[:, j] == pytest.approx(reference, rel=1e-7)


def test_a_prestressed_column_against_differences():
    # Axial compression lowers the bending frequencies (the geometric stiffness of the load); the
    # load's stresses change with EA and the equilibrium with it.
    load = (-0.5 * np.pi**2 * EI / (4 * L**2), -0.05)   # half the Euler load, a little side load
    m, _ = cantilever(load=load)
    params = [("ESTIFF", 1, 2), ("ESTIFF", 4, 1), ("EMASS", 6, 1)]
    s = sensitivity.frequencies(m, params, k=2)
    for j, p in enumerate(params):
        reference = whole(lambda: cantilever(load=load), p, lambda mm: lowest_frequencies(mm, 2))
        assert s.df[:, j] == pytest.approx(reference, rel=1e-7, abs=1e-9 * s.frequencies.max())


# The parallel leaf-spring guide (examples/parallel_leaf_guide.dat): 2 leaves of 4 PLBEAMs each,
# steel 20 x 0.5 mm, 50 mm long; the stage (node 9's side) moves along x.
W, T_LEAF, L_LEAF = 0.02, 0.5e-3, 0.05


def guide(thickness=T_LEAF, stage_mass=0.2):
    m = spacar.read("examples/parallel_leaf_guide.dat")
    section.rectangle(W, thickness, section.STEEL).apply(m, *range(1, 9))
    m.mass(9, stage_mass)
    return m


def leaf_thickness():
    return sensitivity.Dimension(lambda t: section.rectangle(W, t, section.STEEL), T_LEAF, list(range(1, 9)),
                                 name="thickness")


def loaded_compliance(thickness):
    """The drive compliance at the equilibrium under the guide's 1 N."""
    return spacar.compliance(spacar.static(guide(thickness)), 9)[0, 0]


def test_the_guides_drive_compliance_in_the_leaf_thickness():
    s = sensitivity.compliance(guide(), 9, [leaf_thickness(), ("MASS", 9, 1)])
    c = s.C[0, 0]
    EI_leaf = section.STEEL.E * W * T_LEAF**3 / 12
    assert c == pytest.approx(L_LEAF**3 / (24 * EI_leaf), rel=1e-2)    # the leaves' shortening aside
    h = 1e-5 * T_LEAF
    reference = (loaded_compliance(T_LEAF + h) - loaded_compliance(T_LEAF - h)) / (2 * h)
    assert s.dC[0, 0, 0] == pytest.approx(reference, rel=1e-7)
    assert s.dC[0, 0, 0] == pytest.approx(-3 * c / T_LEAF, rel=1e-2)   # C ∝ t⁻³
    assert s.dC[1] == pytest.approx(np.zeros_like(s.C), abs=1e-12 * c)  # no gravity: mass does not matter


def test_the_guides_drive_frequency_in_the_thickness_and_the_stage_mass():
    s = sensitivity.frequencies(guide(), [leaf_thickness(), ("MASS", 9, 1)], k=1)
    for j, make in enumerate((lambda v: guide(thickness=v), lambda v: guide(stage_mass=v))):
        v = (T_LEAF, 0.2)[j]
        h = 1e-5 * v
        values = []
        for sign in (1, -1):
            mm = make(v + sign * h)
            spacar.static(mm)
            values.append(spacar.linearize(mm).eigenfrequencies(k=1)[0])
        assert s.df[0, j] == pytest.approx((values[0] - values[1]) / (2 * h), rel=1e-7)


def ur5(stiffness=1e4):
    """The UR5 of example-robot-data with a torsion spring in each joint (no gravity): its
    modes about the URDF's pose, where it rests unloaded."""
    import importlib.metadata
    import warnings

    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    path = dist.locate_file("cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = spacar.from_urdf(str(path))
    for e, el in m.elements.items():
        if el.type_name == "HINGE":
            m.estiff(e, stiffness)
    return m


def test_the_ur5_with_elastic_joints_lowest_frequency():
    m = ur5()
    hinges = [e for e, el in m.elements.items() if el.type_name == "HINGE"]
    # The links' masses sit on their XYZ nodes (one MASS value); a LAMBDA node's MASS values are
    # the link's inertia tensor: the heaviest link's mass and the inertia of another.
    points = sorted((node.mass[0], n) for n, node in m.core.nodes.items() if len(node.mass) == 1)
    bodies = [n for n, node in m.core.nodes.items() if len(node.mass) == 6]
    params = [("ESTIFF", hinges[1], 1), ("MASS", points[-1][1], 1), ("MASS", bodies[2], 4)]
    s = sensitivity.frequencies(m, params, k=1)
    for j, p in enumerate(params):
        reference = whole(lambda: (ur5(), None), p, lambda mm: lowest_frequencies(mm, 1))
        assert s.df[0, j] == pytest.approx(reference[0], rel=1e-7)


def test_bad_parameters_are_refused_by_name():
    m, _ = cantilever()
    with pytest.raises(spacar.InputError, match="element 99 is not defined"):
        sensitivity.displacements(m, [("ESTIFF", 99, 1)])
    with pytest.raises(spacar.InputError, match="no value 5"):
        sensitivity.displacements(m, [("ESTIFF", 1, 5)])
    with pytest.raises(spacar.InputError, match="ESTIFF, EMASS or MASS"):
        sensitivity.displacements(m, [("EDAMPP", 1, 1)])
    with pytest.raises(spacar.InputError, match="at least one parameter"):
        sensitivity.displacements(m, [])
    with pytest.raises(spacar.InputError, match="positive number"):
        sensitivity.Dimension(lambda t: None, -1.0, [1])
    with pytest.raises(spacar.InputError, match="whole numbers"):
        sensitivity.displacements(m, [("ESTIFF", 1.7, 2)])
    with pytest.raises(spacar.InputError, match="must return a spacar.section.Section"):
        sensitivity.displacements(m, [sensitivity.Dimension(lambda t: 5, 1e-3, 2)])
    with pytest.raises(spacar.InputError, match="k = 99 modes asked for, the model has 24"):
        sensitivity.frequencies(m, ["ESTIFF", 1, 2], k=99)


def test_results_that_are_not_an_equilibrium_of_the_model_are_refused():
    m, _ = cantilever()
    moving = cantilever()[0]
    moving.timestep(5, 0.5)
    with pytest.raises(spacar.InputError, match="not a static equilibrium of this model"):
        sensitivity.displacements(m, [("ESTIFF", 1, 2)], results=spacar.simulate(moving, progress=False))


def test_a_dimension_must_describe_the_model():
    thick = sensitivity.Dimension(lambda t: section.rectangle(W, t, section.STEEL), 0.6e-3, list(range(1, 9)))
    with pytest.raises(spacar.InputError, match="is not the section's at 0.0006"):
        sensitivity.compliance(guide(), 9, [thick])


def test_a_mass_added_where_there_is_none():
    # The stage without mass: dω/dm at m = 0 (a one-sided difference of the whole analysis).
    s = sensitivity.frequencies(guide(stage_mass=0.0), [("MASS", 9, 1)], k=1)
    h = 1e-7
    f = [lowest_frequencies(guide(stage_mass=v), 1)[0] for v in (0.0, h, 2 * h)]
    assert s.df[0, 0] == pytest.approx((-3 * f[0] + 4 * f[1] - f[2]) / (2 * h), rel=1e-7)


def spatial_cantilever(EIy=1.3, EIz=2.0):
    """4 BEAMs along x clamped at nodes 1/2, the tip's LAMBDA node 10."""
    m = spacar.Model()
    for k in range(4):
        m.beam(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4, 0, 1, 0)
        m.x(2 * k + 3, (k + 1) / 4, 0, 0)
        m.dyne(k + 1)
        m.estiff(k + 1, 1e5, 1.0, EIy, EIz)
        m.emass(k + 1, 1.0, 1e-3, 1e-3, 1e-3)
    m.x(1, 0, 0, 0)
    m.fix(1)
    m.fix(2)
    return m


def test_an_unsymmetric_tangent_and_a_repeated_frequency_are_refused():
    m = spatial_cantilever()
    m.force(9, 0.0, 0.0, -0.2)
    m.torqueg(10, 0.3, 0.2, 0.0)     # a dead moment: its load stiffness is not symmetric
    with pytest.raises(spacar.InputError, match="tangent stiffness is not symmetric"):
        sensitivity.frequencies(m, [("ESTIFF", 1, 2)], k=1)
    with pytest.raises(spacar.InputError, match="tangent stiffness is not symmetric"):
        sensitivity.compliance(m, 9, [("ESTIFF", 1, 2)])
    d = sensitivity.displacements(m, [("ESTIFF", 2, 3)])        # the direct method needs no symmetry
    reference = whole(lambda: (_loaded_torqued(), None), ("ESTIFF", 2, 3),
                      lambda mm: spacar.static(mm).node(9).x[-1])
    assert d.node(9)[:, 0] == pytest.approx(reference, rel=1e-7, abs=1e-9 * np.abs(reference).max())
    # A square section: the bending modes come in pairs, whose derivatives are not defined.
    with pytest.raises(spacar.SpacarError, match="modes 1 and 2 have the same frequency"):
        sensitivity.frequencies(spatial_cantilever(2.0, 2.0), [("ESTIFF", 2, 3)], k=1)


def _loaded_torqued():
    m = spatial_cantilever()
    m.force(9, 0.0, 0.0, -0.2)
    m.torqueg(10, 0.3, 0.2, 0.0)
    return m


def test_the_static_results_given_are_the_equilibrium_used():
    m, tip = cantilever()
    res = spacar.static(m)
    given = sensitivity.displacements(m, [("ESTIFF", 1, 2)], results=res)
    solved = sensitivity.displacements(cantilever()[0], [("ESTIFF", 1, 2)])
    assert given.dx == pytest.approx(solved.dx, rel=1e-9, abs=1e-15)
    assert given.labels == ["ESTIFF 1 2"]


def test_a_design_by_newtons_method_with_the_derivative():
    # The leaf thickness that puts the guide's drive mode at 40 Hz, by scipy's Newton with df/dt.
    from scipy.optimize import newton

    def residual_and_slope(t):
        s = sensitivity.frequencies(guide(thickness=t), [sensitivity.Dimension(
            lambda v: section.rectangle(W, v, section.STEEL), t, list(range(1, 9)))], k=1)
        return s.frequencies[0] - 40.0, s.df[0, 0]
    t = newton(lambda v: residual_and_slope(v)[0], T_LEAF, fprime=lambda v: residual_and_slope(v)[1], tol=1e-12)
    assert lowest_frequencies(guide(thickness=t), 1)[0] == pytest.approx(40.0, rel=1e-9)
