"""The eigen-analyses, compliance and state space of large models on the sparse nodal matrices
(issue 34, docs/formulation.md §10): each against an independent reference — the Euler–Bernoulli
frequencies and buckling loads of a cantilever, the dense reduced solution of the same
discretization (Linearization's method="dense", itself tested in test_linearize.py), the tip
compliance L³/3EI, a mass-free model against the same model with masses (buckling does not
depend on mass) — and at sizes where the dense path would not do (memory and time bounded)."""
from __future__ import annotations

import pickle

import numpy as np
import pytest

import spacar
from support.paths import EXAMPLES
from support.planar_models import compressed_cantilever
from support.planar_models import tip_loaded_beam as beam
from support.spatial_models import bathe_bend, cantilever as beam_cantilever

BETA = np.array([1.8751040687119611, 4.694091132974175, 7.854757438237613, 10.995540734875467, 14.13716839104647])


def euler_bernoulli(L=1.2, EI=2.0, rhoA=3.0):
    return BETA**2 * np.sqrt(EI / (rhoA * L**4)) / (2 * np.pi)


def test_lowest_frequencies_equal_the_dense_solution_and_converge():
    lin = spacar.linearize(beam(120))
    assert "sparse nodal" in repr(lin) and len(lin.z_labels) == 360  # > SPARSE_ABOVE: k takes the sparse path
    sparse = lin.eigenfrequencies(k=10)
    dense = lin.eigenfrequencies(k=10, method="dense")
    np.testing.assert_allclose(sparse, dense, rtol=1e-9)
    np.testing.assert_allclose(sparse[:4], euler_bernoulli()[:4], rtol=1e-7)  # cubic elements: h⁴
    f, vz, vx = lin.mode_shapes(k=4)
    fd, vzd, vxd = lin.mode_shapes(k=4, method="dense")
    np.testing.assert_allclose(f, fd, rtol=1e-9)
    signs = np.sign(np.sum(vz * vzd, axis=0))
    np.testing.assert_allclose(vz * signs, vzd, atol=1e-8)
    np.testing.assert_allclose(vx * signs, vxd, atol=1e-8 * np.abs(vxd).max())
    assert np.abs(vz).max(axis=0) == pytest.approx(np.ones(4))  # unit largest component in z


def test_fine_meshes_keep_their_digits():
    """3200 beams: the saddle-point system's condition grows as n², its solves are refined in
    the reduced coordinates (ReducedSystem) and the frequencies come from Rayleigh quotients of
    the elements' energies: the converged mesh gives the Euler–Bernoulli values to 1e-11."""
    lin = spacar.linearize(beam(3200))
    f = lin.eigenfrequencies(k=5)
    np.testing.assert_allclose(f[:4], euler_bernoulli()[:4], rtol=1e-11)


def test_spatial_beams_and_constraints_sparse_against_dense():
    """BEAMs on LAMBDA nodes (L2MIN1 rows in the constraints) and a flexure guide with a rigid
    stage (rigid beam rows), forced onto the sparse path."""
    spatial = beam_cantilever(12, EIy=2.0, EIz=1.0, GIp=0.7, rhoA=0.3, rhoIp=0.01)
    guide = spacar.read(EXAMPLES / "parallel_leaf_guide.dat")
    for e in range(1, 10):
        guide.emass(e, 0.1)
    spacar.static(guide, steps=1)  # at its equilibrium under the example's load
    for model in (spatial, guide):
        lin = spacar.linearize(model)
        k = min(6, len(lin.z_labels) - 2)
        np.testing.assert_allclose(lin.eigenfrequencies(k=k, method="sparse"),
                                   lin.eigenfrequencies(k=k, method="dense"), rtol=1e-9)


def test_buckling_loads_sparse_dense_and_analytic():
    m = compressed_cantilever(40)  # unit compressive load: the factors are the buckling loads
    lin = spacar.linearize(m)
    mu = lin.buckling_factors(k=3, method="sparse")
    np.testing.assert_allclose(mu, lin.buckling_factors(k=3, method="dense"), rtol=1e-9)
    np.testing.assert_allclose(mu, (np.pi / 2) ** 2 * np.array([1, 9, 25]), rtol=1e-5)  # P_cr (2k−1)² π²/4
    mu2, vz, vx = lin.buckling_modes(k=2, method="sparse")
    assert np.abs(vz).max(axis=0) == pytest.approx(np.ones(2))
    # The first mode is the quarter sine wave: of the lateral displacements the tip's is largest.
    lateral = [i for i, (node, component) in enumerate(lin.coordinate_labels) if node % 2 and component == 2]
    assert lateral[np.argmax(np.abs(vx[lateral, 0]))] == lin.coordinate_labels.index((81, 2))


def test_buckling_needs_no_mass():
    """The flexure guide of examples/ has no masses: at its static equilibrium its buckling factors,
    on the sparse path and on the dense one (issue 39: the dense matrices at rest come without the
    equations of motion, M0 = 0), equal those of the same guide with masses; the modes ask for
    masses."""
    def guide(mass):
        m = spacar.read(EXAMPLES / "parallel_leaf_guide.dat")
        m.force(9, 0.0, -100.0)  # a compressive load on the stage
        if mass:
            for e in range(1, 10):
                m.emass(e, 0.1)
        spacar.static(m, steps=1)  # the equilibrium under it
        return m

    free = spacar.linearize(guide(False)).buckling_factors(k=2, method="sparse")
    with_mass = spacar.linearize(guide(True))
    np.testing.assert_allclose(free, with_mass.buckling_factors(k=2, method="sparse"), rtol=1e-12)
    np.testing.assert_allclose(free, with_mass.buckling_factors(k=2, method="dense"), rtol=1e-8)
    massless = spacar.linearize(guide(False))
    assert not massless.M0.any()
    np.testing.assert_allclose(massless.K0, with_mass.K0, rtol=0, atol=1e-9 * np.abs(with_mass.K0).max())
    np.testing.assert_allclose(massless.G0, with_mass.G0, rtol=0, atol=1e-9 * np.abs(with_mass.G0).max())
    np.testing.assert_allclose(free, massless.buckling_factors(k=2, method="dense"), rtol=1e-8)
    for modes in (lambda: massless.eigenfrequencies(2), lambda: massless.eigenfrequencies(2, method="dense"),
                  lambda: massless.state_matrix()):
        with pytest.raises(spacar.SingularMassError, match="needs masses: no node or element"):
            modes()
    with pytest.raises(spacar.SingularMassError, match="call spacar.static"):  # away from its equilibrium
        unloaded = spacar.read(EXAMPLES / "parallel_leaf_guide.dat")
        spacar.linearize(unloaded)


def test_state_space_poles_keep_their_digits():
    """The slow poles of a 200-beam cantilever: the eigenfrequencies (which match Euler–Bernoulli)
    to 1e-9; eigvals of [[0, I], [−M⁻¹K, −M⁻¹D]] missed them by 7e-7."""
    ss = spacar.state_space(beam(200))
    w = np.sort(np.abs(ss.poles().imag))[::2][:5]
    f = ss.linearization.eigenfrequencies()[:5] * 2 * np.pi
    np.testing.assert_allclose(w, f, rtol=1e-9)
    np.testing.assert_allclose(w[:3], 2 * np.pi * euler_bernoulli()[:3], rtol=1e-8)


def test_modal_state_space_of_a_large_model():
    L, EI = 1.2, 2.0
    full = spacar.state_space(beam(200, L=L, EI=EI))
    red = spacar.state_space(beam(200, L=L, EI=EI), modes=30)
    assert red.A.shape == (60, 60) and red.B.shape == (60, 1) and red.D.shape == (2, 1)
    # The static gain stays exact: the truncated modes' static response is the feedthrough.
    assert red.static_gain()[0, 0] == pytest.approx(L**3 / (3 * EI), rel=1e-10)
    assert red.static_gain()[1, 0] == 0.0
    np.testing.assert_allclose(np.sort(np.abs(red.poles().imag))[::2],
                               np.sort(np.abs(full.poles().imag))[::2][:30], rtol=1e-9)
    # Below the truncated modes the position response is that of the full model (the error of
    # the quasi-static correction is of the order (ω/ω31)² of the truncated part).
    gain = L**3 / (3 * EI)
    for f in (0.1, 2.0, 20.0):
        np.testing.assert_allclose(red.frequency_response([f])[0, 0], full.frequency_response([f])[0, 0],
                                   atol=1e-7 * gain)
    with pytest.raises(spacar.InputError, match="modes= needs a state at rest"):
        moving = beam(4)
        spacar.state_space(moving, at=(0.0, np.zeros(12), np.ones(12)), modes=2)


def test_compliance_of_a_fine_mesh_is_exact():
    """The tip compliance L³/3EI of a 1000-beam cantilever, one refined sparse solve per load."""
    L, EI = 1.2, 2.0
    m = beam(1000, L=L, EI=EI, EA=1e6)
    C = spacar.compliance(m, 2001, rotation=2002)
    np.testing.assert_allclose(C[1:, 1:], [[L**3 / (3 * EI), L**2 / (2 * EI)], [L**2 / (2 * EI), L / EI]], rtol=1e-10)
    assert C[0, 0] == pytest.approx(L / 1e6, rel=1e-8)


def test_large_flexures_solve_statically_in_linear_time():
    """The spatial 45° bend of Bathe and Bolourchi (64 BEAMs) and a 3-D parallel leaf-spring guide
    of 400 BEAMs (the issue's cases, timed in benchmarks/statics.py): static solutions in one load
    step, the guide's drive stiffness 24 EI/L³ less the softening of its vertical load."""
    n = 64
    tip = spacar.static(bathe_bend(n), steps=1).node(n + 1).x[-1]
    # Published (Simo and Vu-Quoc; Crisfield): about (47.2, 15.8, 53.4); the torsion constant's
    # value differs between them by a few per cent.
    np.testing.assert_allclose(tip, [47.0, 15.6, 53.5], atol=0.4)
    guide, EI = leaf_guide(200)
    res = spacar.static(guide, steps=1)
    stiffness = 1.0 / res.node(201).x[-1][0]
    assert 0.9 * 24 * EI / 0.05**3 < stiffness < 24 * EI / 0.05**3


def leaf_guide(n, L=0.05, D=0.03, B=0.02, T=0.0005):
    """Two steel leaves of n BEAMs each (along y, thickness T along x, width B along z), clamped
    at y = 0 and welded to a rigid stage at y = L; 1 N along x and −10 N along y on the stage."""
    m = spacar.Model()
    e = 0
    for leaf, x0 in enumerate((0.0, D)):
        base = 1 + leaf * 10000
        for i in range(n + 1):
            m.x(base + i, x0, L * i / n, 0.0)
        for i in range(n):
            e += 1
            m.beam(e, base + i, base + 5000 + i, base + i + 1, base + 5001 + i, 1.0, 0.0, 0.0)
            m.rlse(e)
        m.fix(base)
        m.fix(base + 5000)
        for i in range(1, n + (1 if leaf == 0 else 0)):  # leaf 2's top follows the stage
            m.dynx(base + i)
            m.dynx(base + 5000 + i)
    m.beam(e + 1, 1 + n, 5001 + n, 10001 + n, 15001 + n, 0.0, 1.0, 0.0)  # the rigid stage
    steel_E, steel_G = 2.1e11, 8.1e10
    EA, GJ = steel_E * B * T, steel_G * B * T**3 / 3
    EI_thin, EI_wide = steel_E * B * T**3 / 12, steel_E * T * B**3 / 12
    for k in range(1, e + 1):
        m.estiff(k, EA, GJ, EI_wide, EI_thin)
    m.force(1 + n, 1.0, -10.0, 0.0)
    return m, EI_thin


def test_nodal_linearization_pickles_with_its_dense_matrices():
    lin = spacar.linearize(beam(6))
    back = pickle.loads(pickle.dumps(lin))
    np.testing.assert_array_equal(back.M0, lin.M0)
    np.testing.assert_allclose(back.eigenfrequencies(), lin.eigenfrequencies(), rtol=1e-12)
    with pytest.raises(spacar.InputError, match="sparse eigen-analysis needs"):
        back.eigenfrequencies(k=2, method="sparse")


def beam_line(n, ea, ei, damping=0.0, point_mass=0.0):
    """n flexible PLBEAMs of unit mass along x from 0 to 1 (every deformation a DOF; EDAMPP 0 and
    `damping` if given), node 1 fixed; a point mass on every other node if given."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n, 0.0)
        m.estiff(k, ea, ei)
        if damping:
            m.edampp(k, 0.0, damping)
        m.emass(k, 1.0)
        m.dyne(k, 1, 2, 3)
        if point_mass and k % 2 == 0:
            m.mass(2 * k + 1, point_mass)
    m.fix(1)
    return m


def test_generalized_alpha_on_a_large_model_solves_sparse():
    """From 100 DOFs generalized-α's Newton matrix goes through the sparse saddle-point system
    (Simulation::sparse_newton): a damped cantilever of 40 PLBEAMs (120 DOFs) under gravity
    agrees with Radau5 (dense Jacobian) at a tight tolerance, and 600 PLBEAMs (1800 DOFs) run
    within a 10 MB memory limit, where the dense Jacobian alone would need 26 MB."""
    def hanging(n):
        m = beam_line(n, 1e2, 1.0, damping=1e-3)
        m.fix(2)
        m.gravity(0.0, -1.0)
        m.timestep(10, 0.2)
        return m

    ref = hanging(40)
    ref.epsint(1e-10)
    ref.epsind(1e-10)
    reference = spacar.simulate(ref, method="radau5").node(81).x
    m = hanging(40)
    m.epsint(1e-7)
    m.epsind(1e-7)
    res = spacar.simulate(m, method="generalized_alpha")
    assert np.abs(res.node(81).x - reference).max() < 2e-6
    assert np.abs(reference[-1, 1]) > 0.01  # it moved
    old = spacar.memory_limit()
    try:
        spacar.set_memory_limit(10_000_000)
        big = hanging(600)
        big.timestep(2, 1e-4)
        out = spacar.simulate(big, method="generalized_alpha", fixed_step=5e-5)
        assert np.isfinite(out.x).all() and out.node(1201).x[-1, 1] < 0.0
    finally:
        spacar.set_memory_limit(old)


def test_generalized_alpha_error_control_on_the_sparse_newton_matrix_of_a_swinging_beam():
    """From 100 DOFs generalized-α's error filter is one solve with the sparse saddle-point system
    (the nodal load M Z v), and the nodal positions' error is that solve's Z x, Z at the state of
    the Newton matrix's last refresh. A rotating case with point masses: 34 flexible PLBEAMs
    (103 DOFs) hinged at node 1, horizontal at the start, swing 37° down under gravity in 0.3 s;
    the tip within EPSINT of a Richardson-extrapolated generalized-α reference at fixed steps
    (which agrees with DOP853 and Radau5 at EPS 1e-8 to 4e-13 m)."""
    n = 34

    def swinging(eps):
        m = beam_line(n, 1e3, 2.0, point_mass=0.05)
        m.dynx(2)
        m.gravity(0.0, -9.81)
        m.timestep(5, 0.3)
        m.epsint(eps)
        m.epsind(eps)
        return m

    coarse, fine = (spacar.simulate(swinging(1e-10), method="generalized_alpha", rho_inf=1.0, fixed_step=h)
                    .node(2 * n + 1).x for h in (4e-5, 2e-5))
    reference = fine + (fine - coarse) / 3.0  # second order
    eps = 1e-4
    res = spacar.simulate(swinging(eps), method="generalized_alpha")
    assert res.stats["jacobians"] >= 1
    assert np.arctan2(-reference[-1, 1], reference[-1, 0]) > 0.6  # it swung (37°)
    error = np.abs(res.node(2 * n + 1).x - reference).max()
    assert error < 0.5 * eps, error  # measured: 0.01 EPSINT
