"""Linearized equations, eigenfrequencies, mode shapes, buckling (issue #5, formulation.md §7,
§10.3, §10.4).

* cantilever frequencies (planar PLBEAM, spatial BEAM) reproduce the consistent-mass table of
  §10.3 and converge with the mesh to the Euler–Bernoulli values; the first mode shape at the
  nodes against the analytic one;
* Euler buckling of PLBEAMNL / PLBEAM / BEAMNL columns, clamped–free and pinned–pinned: the
  table of §10.4;
* rotating beams: lead-lag (planar) and flapwise (spatial) centrifugal stiffening against a
  Rayleigh–Ritz reference computed here, Southwell coefficient 1.1933;
* the matrices one by one: M0 symmetric positive definite, C0 = N0 = 0 in static
  equilibrium, D0 from EDAMPP, gyroscopic C0 of a symmetric rotor (free and in a gimbal), the
  analytic + difference parts against a full difference Jacobian of the reduced residual
  computed here from the public evaluation;
* LINE parameters (rigid rod of the slider-crank): frequencies along the motion, r0 = the
  nominal reaction stress;
* eigenvalues of a damped oscillator, the state-space helper, the linear response against the
  nonlinear simulation (difference shrinking quadratically with the disturbance);
* `spacar run` prints eigenfrequencies (LINEAR 1) and buckling factors (LINEAR 2).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
import scipy.optimize
from numpy.polynomial import Legendre
from numpy.polynomial import legendre as gauss_legendre

import spacar
from spacar.cli import main
from support.equilibrium import static_equilibrium
from support.paths import EXAMPLES
from support.simulation import assembled

EXAMPLE = EXAMPLES / "slidercrank.dat"


def omegas(lin):
    """Circular eigenfrequencies (rad/s) of the undamped equations, ascending."""
    return 2 * np.pi * lin.eigenfrequencies()


# --------------------------------------------------------------------------------------------
# Models
# --------------------------------------------------------------------------------------------

def planar_beam_chain(n, element="PLBEAM", L=1.0, EI=1.0, rho=1.0):
    """n equal planar beams along x from node 1/2 to 2n+1/2n+2, e1 rigid, bending DYNE."""
    m = spacar.Model()
    add = getattr(m, element.lower())
    for k in range(n):
        add(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4)
        m.x(2 * k + 3, L * (k + 1) / n, 0.0)
        m.estiff(k + 1, 0.0, EI)
        m.emass(k + 1, rho)
        m.dyne(k + 1, 2, 3)
    return m


def spatial_beam_chain(n, element="BEAM", EIy=1.0, EIz=1.0):
    """n equal BEAMs along x, e1 and the (massless) torsion e2 rigid, bending e3..e6 DYNE."""
    m = spacar.Model()
    add = getattr(m, element.lower())
    for k in range(n):
        add(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4, 0.0, 1.0, 0.0)
        m.x(2 * k + 3, (k + 1) / n, 0.0, 0.0)
        m.estiff(k + 1, 0.0, 1.0, EIy, EIz)
        m.emass(k + 1, 1.0)
        m.dyne(k + 1, 3, 4, 5, 6)
    return m


def cantilever(n):
    m = planar_beam_chain(n)
    m.fix(1)
    m.fix(2)
    return m


# --------------------------------------------------------------------------------------------
# Euler–Bernoulli references
# --------------------------------------------------------------------------------------------

def eb_cantilever_roots(k=4):
    """β_i L of cos·cosh + 1 = 0."""
    return np.array([scipy.optimize.brentq(lambda b: math.cos(b) * math.cosh(b) + 1, (i + 0.3) * math.pi,
                                           (i + 0.7) * math.pi) for i in range(k)])


def eb_mode(b, x):
    s = (math.cosh(b) + math.cos(b)) / (math.sinh(b) + math.sin(b))
    w = np.cosh(b * x) - np.cos(b * x) - s * (np.sinh(b * x) - np.sin(b * x))
    dw = b * (np.sinh(b * x) + np.sin(b * x) - s * (np.cosh(b * x) - np.cos(b * x)))
    return w, dw


def rayleigh_ritz_rotating(Omega, lag=False, N=12):
    """ω² of a uniform cantilever (EI = ρA = L = 1) rotating about a perpendicular axis through
    its root, by Rayleigh–Ritz with w'' spanned by Legendre polynomials (w(0) = w'(0) = 0):
    EI w'''' − (T w')' [− ρAΩ² w in-plane] + ρA ẅ = 0, T(x) = ρAΩ²(L² − x²)/2 (inextensible).
    Also returns the first-order (Southwell) coefficient of the first mode,
    α = ∫T w'² / (Ω² ∫ρA w²) with the non-rotating mode shape."""
    xg, wg = gauss_legendre.leggauss(60)
    x, wq = 0.5 * (xg + 1), 0.5 * wg
    W, W1, W2 = [], [], []
    for j in range(N):
        P = Legendre.basis(j, domain=[0, 1])
        w = P.integ(2, lbnd=0)
        W.append(w(x))
        W1.append(w.deriv(1)(x))
        W2.append(P(x))
    W, W1, W2 = np.array(W), np.array(W1), np.array(W2)
    M = (W * wq) @ W.T
    Kb = (W2 * wq) @ W2.T
    Kc = (W1 * wq * 0.5 * (1 - x**2)) @ W1.T
    K = Kb + Omega**2 * (Kc - M if lag else Kc)
    w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
    _, V = scipy.linalg.eigh(Kb, M)
    v = V[:, 0]
    return w2, (v @ Kc @ v) / (v @ M @ v)


# --------------------------------------------------------------------------------------------
# Cantilever frequencies (formulation.md §10.3)
# --------------------------------------------------------------------------------------------

TABLE_10_3 = {1: ("3.532732", "34.80689"), 2: ("3.517715", "22.22147", "75.15708"),
              4: ("3.516130", "22.06017", "62.17489"), 8: ("3.516023", "22.03625", "61.73474")}


def close_to_printed(value, text):
    """|value − printed| within half a unit of the printed last digit."""
    decimals = len(text.split(".")[1])
    return abs(value - float(text)) <= 0.5 * 10.0**-decimals * (1 + 1e-6)


@pytest.mark.parametrize("n", [1, 2, 4, 8])
def test_planar_cantilever_frequencies_table(n):
    w = omegas(spacar.linearize(cantilever(n)))
    for value, text in zip(w, TABLE_10_3[n]):
        assert close_to_printed(value, text), (n, value, text)


@pytest.mark.parametrize("n", [1, 2, 4, 8])
def test_spatial_cantilever_frequencies_table_twice(n):
    """BEAM cantilever, EIy = EIz: every frequency of the table twice (bending about y and z)."""
    m = spatial_beam_chain(n)
    m.fix(1)
    m.fix(2)
    w = omegas(spacar.linearize(m))
    for i, text in enumerate(TABLE_10_3[n]):
        assert close_to_printed(w[2 * i], text) and close_to_printed(w[2 * i + 1], text)


def test_spatial_cantilever_unequal_bending_stiffness():
    m = spatial_beam_chain(4, EIz=4.0)
    m.fix(1)
    m.fix(2)
    w = omegas(spacar.linearize(m))
    ref = [float(t) for t in TABLE_10_3[4]]
    assert np.allclose(w[:4], [ref[0], 2 * ref[0], ref[1], 2 * ref[1]], rtol=2e-7)


def test_cantilever_frequencies_converge_to_euler_bernoulli():
    """Errors of ω1..ω3 fall monotonically with the mesh at the h⁴ rate of cubic elements."""
    exact = eb_cantilever_roots(3) ** 2
    errors = []
    for n in (2, 4, 8, 16):
        for model in (cantilever(n),):
            w = omegas(spacar.linearize(model))[:3]
            errors.append(np.abs(w - exact) / exact)
    errors = np.array(errors)
    assert np.all(errors[1:] < errors[:-1])
    assert np.all(errors[-2] / errors[-1] > 12)          # 8 → 16: rate ≈ 16
    assert np.all(errors[-1] < [2e-7, 6e-6, 5e-5])
    spatial = spatial_beam_chain(16)
    spatial.fix(1)
    spatial.fix(2)
    w3 = omegas(spacar.linearize(spatial))[:6:2]
    assert np.allclose(w3, omegas(spacar.linearize(cantilever(16)))[:3], rtol=1e-10)


def test_fine_mesh_frequencies_with_sparse_residual():
    """200 DOFs: the perturbed residuals of the finite differences come from sparse solves
    (no transfer functions); ω1..ω3 still reach Euler–Bernoulli at the h⁴ rate."""
    exact = eb_cantilever_roots(3) ** 2
    w = omegas(spacar.linearize(cantilever(100)))[:3]
    assert np.all(np.abs(w - exact) / exact < [1e-9, 1e-8, 1e-7])


def test_first_mode_shape_at_the_nodes():
    """Nodal displacements and rotations of the first mode (mode_shapes mapped back to the
    nodal coordinates) against the Euler–Bernoulli mode, normalised at the tip."""
    b = eb_cantilever_roots(1)[0]
    w_tip = eb_mode(b, 1.0)[0]
    prev = None
    for n in (4, 8):
        lin = spacar.linearize(cantilever(n))
        freq, shapes_z, shapes_x = lin.mode_shapes()
        assert np.allclose(shapes_x, lin.DF @ shapes_z)
        assert np.isclose(2 * np.pi * freq[0], omegas(lin)[0])
        labels = lin.coordinate_labels
        ys = [i for i, (node, c) in enumerate(labels) if node % 2 == 1 and c == 2]
        rots = [i for i, (node, c) in enumerate(labels) if node % 2 == 0]
        xn = np.array([(labels[i][0] - 1) / 2 / n for i in ys])
        v = shapes_x[:, 0] / shapes_x[ys[-1], 0]
        w, dw = eb_mode(b, xn)
        err = max(np.abs(v[ys] - w / w_tip).max(), np.abs(v[rots] - dw / w_tip).max())
        assert err < {4: 1e-6, 8: 2e-8}[n]
        if prev:
            assert err < prev / 30
        prev = err


# --------------------------------------------------------------------------------------------
# Buckling (formulation.md §10.4)
# --------------------------------------------------------------------------------------------

TABLE_10_4 = {("cantilever", "PLBEAMNL"): (2.4859617, 2.4686648, 2.4674819),
              ("cantilever", "PLBEAM"): (3.0000000, 2.5966605, 2.4992702),
              ("pinned", "PLBEAMNL"): (12.000000, 9.9438468, 9.8746590),
              ("pinned", "PLBEAM"): (None, 12.000000, 10.386642)}


def column(n, case, element):
    """Unit compressive load at the tip, EI = L = 1, e1 rigid. Cantilever: node 1/2 clamped.
    Pinned–pinned: node 1 pinned, the tip on a roller (y fixed, x free)."""
    spatial = element.startswith("BEAM")
    m = spatial_beam_chain(n, element) if spatial else planar_beam_chain(n, element)
    tip = 2 * n + 1
    m.fix(1)
    if case == "cantilever":
        m.fix(2)
    elif spatial:
        m.fix(tip, 2, 3)
        m.fix(2, 2)  # the twist of the column (what `spacar check` names otherwise)
    else:
        m.fix(tip, 2)
    m.force(tip, *([-1.0, 0.0, 0.0] if spatial else [-1.0, 0.0]))
    m.linear(2)
    return m


@pytest.mark.parametrize("case, element", list(TABLE_10_4))
def test_buckling_table(case, element):
    for n, ref in zip((1, 2, 4), TABLE_10_4[(case, element)]):
        mu = spacar.linearize(column(n, case, element)).buckling_factors()
        if ref is None:
            assert len(mu) == 0  # one chord-only element has no bending–axial coupling
        else:
            assert abs(mu[0] - ref) <= 1e-7 * ref, (n, mu[0], ref)


@pytest.mark.parametrize("case", ["cantilever", "pinned"])
def test_beamnl_buckling_both_planes(case):
    exact = math.pi**2 / 4 if case == "cantilever" else math.pi**2
    errors = []
    for n, ref in zip((1, 2, 4), TABLE_10_4[(case, "PLBEAMNL")]):
        mu = spacar.linearize(column(n, case, "BEAMNL")).buckling_factors()
        assert abs(mu[0] - ref) <= 1e-7 * ref and abs(mu[1] - ref) <= 1e-7 * ref
        errors.append(mu[0] / exact - 1)
    assert 0 < errors[2] < errors[1] < errors[0]
    assert errors[2] < 1e-3


def test_buckling_uses_reaction_stress_and_scales_with_load():
    """G0 comes from the reaction stress σ1 of the rigid e1 (no stiffness on e1): doubling the
    load halves the multipliers; a tensile load gives negative ones."""
    mu1 = spacar.linearize(column(2, "cantilever", "PLBEAMNL")).buckling_factors()[0]
    m = column(2, "cantilever", "PLBEAMNL")
    m.force(5, -2.0, 0.0)
    assert np.isclose(spacar.linearize(m).buckling_factors()[0], mu1 / 2, rtol=1e-12)
    m.force(5, 1.0, 0.0)
    assert np.isclose(spacar.linearize(m).buckling_factors()[0], -mu1, rtol=1e-12)


# --------------------------------------------------------------------------------------------
# Rotating beams: centrifugal stiffening
# --------------------------------------------------------------------------------------------

def rotating_planar(n, Omega):
    """PLBEAMNL cantilever on a hub: the hub angle β2 is INPUTX at constant speed Ω."""
    m = planar_beam_chain(n, "PLBEAMNL")
    m.fix(1)
    m.inputx(2, 1)
    m.xd(2, 1, Omega)
    return m


def rotating_spatial(n, Omega, element="BEAMNL"):
    """BEAMNL cantilever along x on a hub turning about z: HINGE 1000 between the fixed LAMBDA
    node 1000 and the hub node 2 with e1 INPUTE at constant rate Ω. Flapwise = out of the
    plane of rotation (bending about local y, e3/e4); lead-lag = in the plane (e5/e6)."""
    m = spatial_beam_chain(n, element)
    m.hinge(1000, 1000, 2, 0.0, 0.0, 1.0)
    m.fix(1000)
    m.fix(1)
    m.inpute(1000, 1)
    m.ed(1000, 1, Omega)
    return m


def steady(n_dof, t=0.5):
    return (t, np.zeros(n_dof), np.zeros(n_dof))


def test_rotating_beam_lead_lag_planar():
    """In the plane of rotation ω² = ω_flap²(Ω) − Ω² (centrifugal softening of the in-plane
    motion): against Rayleigh–Ritz, converging with the mesh."""
    for Omega in (1.0, 3.0):
        ref = rayleigh_ritz_rotating(Omega, lag=True)[0][:2]
        err = [np.abs(omegas(spacar.linearize(rotating_planar(n, Omega), steady(2 * n)))[:2] ** 2 - ref) / ref
               for n in (4, 8)]
        assert np.all(err[1] < err[0] / 10) and np.all(err[1] < [3e-5, 3e-4])


def test_rotating_beam_flapwise_stiffening_spatial():
    """First and second flapwise and lead-lag ω² of the hub-driven BEAMNL beam against
    Rayleigh–Ritz at Ω = 2 (first flapwise ω² from 12.36 to 17.12)."""
    Omega = 2.0
    flap = rayleigh_ritz_rotating(Omega)[0][:2]
    lag = rayleigh_ritz_rotating(Omega, lag=True)[0][:2]
    lin = spacar.linearize(rotating_spatial(8, Omega), steady(32))
    w2 = omegas(lin)[:4] ** 2
    assert np.allclose(w2, sorted([lag[0], flap[0], lag[1], flap[1]]), rtol=3e-4)
    assert abs(w2[1] / flap[0] - 1) < 1e-5
    # Which is which: the flapwise mode moves the nodes along z only.
    _, _, shapes = lin.mode_shapes()
    z_rows = [i for i, (node, c) in enumerate(lin.coordinate_labels) if node % 2 == 1 and node < 1000 and c == 3]
    y_rows = [i for i, (node, c) in enumerate(lin.coordinate_labels) if node % 2 == 1 and node < 1000 and c == 2]
    assert np.abs(shapes[y_rows, 1]).max() < 1e-8 * np.abs(shapes[z_rows, 1]).max()
    assert np.abs(shapes[z_rows, 0]).max() < 1e-8 * np.abs(shapes[y_rows, 0]).max()


def test_southwell_coefficient():
    """ω1² = ω0² + α Ω² for small Ω: α from spacar (8 BEAMNL elements) against the first-order
    Rayleigh–Ritz coefficient (1.19334, the classical 1.1933 of a uniform blade without hub
    radius); the in-plane coefficient is α − 1."""
    _, alpha_ref = rayleigh_ritz_rotating(0.0)
    assert abs(alpha_ref - 1.1933) < 1e-4
    Omega = 0.01
    w0 = omegas(spacar.linearize(rotating_spatial(8, 0.0), steady(32)))[:2] ** 2
    w1 = omegas(spacar.linearize(rotating_spatial(8, Omega), steady(32)))[:2] ** 2
    lag, flap = (w1 - w0) / Omega**2
    assert abs(flap - alpha_ref) < 5e-5
    assert abs(lag - (alpha_ref - 1)) < 5e-5


def test_rotating_linearization_is_the_same_all_along_the_steady_motion():
    """The state of the steady rotation at a late time (hub turned by 10 rad, beyond the
    branch where one Newton solve from the assembled geometry folds the beam back) and the
    linearizations recorded at the output times of a run (LINEAR 1) are all the same."""
    m = rotating_planar(4, 2.0)
    ref = omegas(spacar.linearize(m, steady(8, 0.0)))
    for t in (1.0, 2.0, 5.0):
        assert np.allclose(omegas(spacar.linearize(m, steady(8, t))), ref, rtol=1e-9)
    m.linear(1)
    m.timestep(4, 2.0)
    m.epsint(1e-9)  # the integrated state must follow the steady motion to the same accuracy
    m.epsind(1e-9)
    res = m.run()
    assert len(res.linearizations) == 5
    for lin in res.linearizations:
        assert np.allclose(omegas(lin), ref, rtol=1e-9)
    spatial = rotating_spatial(3, 2.0)
    ref = omegas(spacar.linearize(spatial, steady(12, 0.0)))
    assert np.allclose(omegas(spacar.linearize(spatial, steady(12, 5.0))), ref, rtol=1e-9)


# --------------------------------------------------------------------------------------------
# The matrices one by one
# --------------------------------------------------------------------------------------------

def gimbal_rotor(A=2.0, C=5.0, Omega=3.0, k=7.0):
    """Symmetric rotor (A, A, C) in a Cardan suspension: HINGE 1 about x (ground 1 → gimbal 2,
    DYNE θx), HINGE 2 about y (gimbal 2 → gimbal 3, DYNE θy), both with torsion springs k;
    HINGE 3 about z (gimbal 3 → rotor 4) turns at constant rate Ω (INPUTE)."""
    m = spacar.Model()
    m.hinge(1, 1, 2, 1.0, 0.0, 0.0)
    m.hinge(2, 2, 3, 0.0, 1.0, 0.0)
    m.hinge(3, 3, 4, 0.0, 0.0, 1.0)
    m.fix(1)
    m.dyne(1, 1)
    m.dyne(2, 1)
    m.estiff(1, k)
    m.estiff(2, k)
    m.inpute(3, 1)
    m.ed(3, 1, Omega)
    m.mass(4, A, 0.0, 0.0, A, 0.0, C)
    return m


def spinning_top(A=2.0, C=5.0, Omega=3.0):
    """A free rigid body on one LAMBDA node (DYNX λ1..λ3) spinning about its symmetry axis z."""
    m = spacar.Model()
    m.lambda_(1, 1.0, 0.0, 0.0, 0.0)
    m.mass(1, A, 0.0, 0.0, A, 0.0, C)
    m.dynx(1, 2, 3, 4)
    m.xd(1, 4, Omega / 2)
    return m


def line_slider_crank():
    """The manual's slider-crank with a rigid rod: the bending deformations are LINE."""
    return spacar.read_string(EXAMPLE.read_text().replace("DYNE", "LINE").replace("Timestep 100 5.0", ""))


def test_mass_matrix_symmetric_positive_definite():
    models = [(cantilever(4), None), (spatial_beam_chain(2), None), (gimbal_rotor(), None),
              (spinning_top(), None), (rotating_spatial(3, 2.0), steady(12)), (line_slider_crank(), (0.7, [], []))]
    models[1][0].fix(1)
    models[1][0].fix(2)
    for model, state in models:
        M0 = spacar.linearize(model, state).M0
        assert np.abs(M0 - M0.T).max() <= 1e-14 * np.abs(M0).max()
        assert np.linalg.eigvalsh(M0).min() > 0


def test_static_equilibrium_has_no_velocity_or_dynamic_stiffness_terms():
    """A PLBEAMNL cantilever deflected by a tip load and gravity, in static equilibrium: C0 = 0
    exactly (no velocities), N0 = 0 to difference noise; G0 carries the load stiffness."""
    n = 4
    m = planar_beam_chain(n, "PLBEAMNL")
    m.fix(1)
    m.fix(2)
    m.force(2 * n + 1, 0.0, -1.0)
    m.gravity(0.0, -1.0)
    m.epskin(1e-12)
    _, q = static_equilibrium(m)
    lin = spacar.linearize(m, (0.0, q, np.zeros(2 * n)))
    scale = np.abs(lin.K0).max()
    assert np.abs(lin.C0).max() == 0.0
    assert np.abs(lin.N0).max() <= 1e-9 * scale
    assert np.abs(lin.G0).max() > 1e-2 * scale
    # Same for the hanging double pendulum (geometric stiffness from gravity only).
    p = spacar.Model()
    p.plbeam(1, 1, 2, 3, 4)
    p.plbeam(2, 3, 5, 6, 7)
    p.x(3, 0.0, -1.0)
    p.x(6, 0.0, -2.0)
    p.fix(1)
    p.dynx(2, 1)
    p.dynx(5, 1)
    p.mass(3, 1.0)
    p.mass(6, 1.0)
    p.gravity(0.0, -9.81)
    lin = spacar.linearize(p)
    assert np.abs(lin.C0).max() == 0.0 and np.abs(lin.N0).max() <= 1e-9 * np.abs(lin.G0).max()
    assert np.abs(lin.K0).max() == 0.0
    # Textbook double pendulum (m = l = 1): ω² = (2 ∓ √2) g.
    assert np.allclose(omegas(lin) ** 2, [(2 - math.sqrt(2)) * 9.81, (2 + math.sqrt(2)) * 9.81], rtol=1e-9)


@pytest.mark.parametrize("element", ["BEAM", "BEAMNL"])
def test_static_equilibrium_spatial_follower_torque_and_gravity(element):
    """Spatial cantilever deflected by a dead force, a body-fixed torque (TORQUEL, follower)
    and gravity on the beam masses, in static equilibrium: N0 = 0, so the analytic G0 — stress
    Hessians plus the load stiffness of TORQUEL and of the beam gravity tangent terms — makes
    up the whole difference Jacobian beyond K0."""
    m = spatial_beam_chain(3, element)
    m.fix(1)
    m.fix(2)
    m.torquel(8, 0.3, -0.2, 0.5)
    m.force(7, 0.2, 0.1, -0.4)
    m.gravity(0.1, -0.5, -1.0)
    m.epskin(1e-13)
    _, q = static_equilibrium(m)
    lin = spacar.linearize(m, (0.0, q, np.zeros(len(q))))
    scale = np.abs(lin.K0).max()
    assert np.abs(q).max() > 0.01 and np.abs(lin.G0).max() > 0.02 * scale
    assert np.abs(lin.C0).max() == 0.0 and np.abs(lin.N0).max() <= 1e-9 * scale
    assert np.abs(lin.G0 - lin.G0.T).max() > 1e-3  # the follower torque is not conservative


def test_damping_matrix_from_edampp():
    """D0 = DF^eᵀ D_v DF^e: for PLBEAM EDAMPP (0, d) the same form as ESTIFF (0, EI), so
    D0 = (d/EI) K0; only D0 changes."""
    plain = spacar.linearize(cantilever(3))
    m = cantilever(3)
    for k in (1, 2, 3):
        m.edampp(k, 0.0, 0.05)
    lin = spacar.linearize(m)
    assert np.allclose(lin.D0, 0.05 * lin.K0, rtol=1e-14, atol=1e-14 * np.abs(lin.K0).max())
    for name in ("M0", "K0", "G0"):
        assert np.array_equal(getattr(lin, name), getattr(plain, name))
    assert np.abs(lin.C0).max() <= 1e-12 * np.abs(lin.D0).max()  # C0 = ∂R/∂ż − D0: round-off


def test_damped_oscillator_eigenvalues():
    """Mass m on a PLTRUSS spring–damper (EA, EDAMPP d): λ = −ζω ± iω√(1 − ζ²)."""
    EA, d, mass, L = 50.0, 0.8, 2.0, 1.0
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(2, L, 0.0)
    m.fix(1)
    m.fix(2, 2)
    m.estiff(1, EA)
    m.edampp(1, d)
    m.mass(2, mass)
    m.dyne(1, 1)
    lin = spacar.linearize(m)
    k, c = EA / L, d / L
    w = math.sqrt(k / mass)
    zeta = c / (2 * mass * w)
    assert np.allclose([lin.M0[0, 0], lin.D0[0, 0], lin.K0[0, 0]], [mass, c, k], rtol=1e-14)
    assert lin.C0[0, 0] == 0.0 and abs(lin.N0[0, 0]) <= 1e-10 * k
    lam = lin.eigenvalues()
    expected = np.array([-zeta * w - 1j * w * math.sqrt(1 - zeta**2), -zeta * w + 1j * w * math.sqrt(1 - zeta**2)])
    assert np.allclose(np.sort_complex(lam), np.sort_complex(expected), rtol=1e-10)


def test_state_space_consistent_with_eigenvalues():
    m = cantilever(3)
    for k in (1, 2, 3):
        m.edampp(k, 0.0, 0.02)
    lin = spacar.linearize(m)
    A, B, C, D = lin.state_space()
    n = lin.M0.shape[0]
    assert A.shape == (2 * n, 2 * n) and B.shape == (2 * n, n) and C.shape == (n, 2 * n) and D.shape == (n, n)
    assert np.allclose(np.sort_complex(np.linalg.eigvals(A)), np.sort_complex(lin.eigenvalues()), rtol=1e-10)
    # Static gain −C A⁻¹ B: the compliance (K0 + N0 + G0)⁻¹, in z and in the nodal coordinates.
    K = lin.stiffness
    assert np.allclose(-C @ np.linalg.solve(A, B), np.linalg.inv(K), rtol=1e-8, atol=1e-12)
    Ax, Bx, Cx, Dx = lin.state_space(outputs="x")
    assert np.allclose(-Cx @ np.linalg.solve(Ax, Bx), lin.DF @ np.linalg.inv(K), rtol=1e-8, atol=1e-12)
    with pytest.raises(spacar.InputError):
        lin.state_space(outputs="e")


def test_gyroscopic_matrix_of_a_rotor_in_a_gimbal():
    """Linearized about the steady spin: M0 = A I, C0 = CΩ [[0, 1], [−1, 0]] (skew), K0 = k I,
    N0 + G0 = 0; eigenvalues ±iω of forward and backward whirl, Aω² ∓ CΩω − k = 0."""
    A, C, Omega, k = 2.0, 5.0, 3.0, 7.0
    lin = spacar.linearize(gimbal_rotor(A, C, Omega, k), (0.7, np.zeros(2), np.zeros(2)))
    assert np.allclose(lin.M0, A * np.eye(2), rtol=0, atol=1e-14)
    assert np.allclose(lin.C0, C * Omega * np.array([[0.0, 1.0], [-1.0, 0.0]]), rtol=0, atol=1e-12)
    assert np.allclose(lin.K0, k * np.eye(2), rtol=0, atol=1e-14) and np.all(lin.D0 == 0)
    assert np.abs(lin.N0 + lin.G0).max() <= 1e-9
    whirl = sorted(abs(s * C * Omega + math.sqrt((C * Omega) ** 2 + 4 * A * k)) / (2 * A) for s in (1, -1))
    lam = lin.eigenvalues()
    assert np.abs(lam.real).max() < 1e-10
    assert np.allclose(sorted(set(np.round(np.abs(lam.imag), 12))), whirl, rtol=1e-10)


def test_gyroscopic_matrix_of_a_free_spinning_top():
    """One LAMBDA node, DOFs λ1..λ3, spinning about its symmetry axis at t = 0
    (λ = (1, 0, 0, 0), λ̇3 = Ω/2): from T = ½ω'ᵀJω', ω' = 2Gλ̇ with λ0 = √(1 − λ̄·λ̄), the
    gyroscopic coupling of λ1 and λ2 is C0 = 4(C − A)Ω [[0, 1], [−1, 0]]; M0 = 4 diag(A, A, C)."""
    A, C, Omega = 2.0, 5.0, 3.0
    lin = spacar.linearize(spinning_top(A, C, Omega))
    assert np.allclose(lin.M0, 4 * np.diag([A, A, C]), rtol=0, atol=1e-13)
    expected = np.zeros((3, 3))
    expected[0, 1], expected[1, 0] = 4 * (C - A) * Omega, -4 * (C - A) * Omega
    assert np.allclose(lin.C0, expected, rtol=0, atol=1e-12)
    assert np.allclose(lin.C0, -lin.C0.T, rtol=0, atol=1e-12)


def reduced_residual_jacobian(model, t, z0, zd0, zdd0, h=1e-5):
    """∂R/∂z and ∂R/∂ż of R(z, ż) = M̄(z)(z̈0 − q̈(z, ż)) — the reduced residual of
    formulation.md §7.2 written with the public evaluation of q̈ and M̄ — by central
    differences (the model's LINE parameters, if any, must be DYNE here)."""
    sim = assembled(model.copy())

    def R(z, zd):
        sim.move_to(t, z, zd)
        return np.array(sim.data.Mbar) @ (zdd0 - np.array(sim.data.qdd))

    n = len(z0)
    Jz, Jzd = np.empty((n, n)), np.empty((n, n))
    for j in range(n):
        dz = np.zeros(n)
        dz[j] = h
        Jz[:, j] = (R(z0 + dz, zd0) - R(z0 - dz, zd0)) / (2 * h)
        Jzd[:, j] = (R(z0, zd0 + dz) - R(z0, zd0 - dz)) / (2 * h)
    return R(z0, zd0), Jz, Jzd, np.array(sim.data.Mbar)


def test_analytic_and_difference_parts_reproduce_the_full_jacobian():
    """K0 + N0 + G0 and C0 + D0 against the difference Jacobian of the reduced residual, and
    M0 against M̄: the moving slider-crank with LINE parameters (r0 ≠ 0, nominal ż of the
    LINE parameters 0), the gimbal rotor and the rotating beam."""
    text = EXAMPLE.read_text().replace("Timestep 100 5.0", "")
    z4, z2, z6 = np.zeros(4), np.array([0.01, -0.02]), 1e-3 * np.arange(1, 7)
    cases = [  # (model, the same with LINE → DYNE, t, z, ż); LINE parameters: z = ż = 0
        (line_slider_crank(), (0.7, [], []), spacar.read_string(text), (0.7, z4, z4)),
        (gimbal_rotor(), (0.7, z2, np.array([0.3, 0.1])), None, None),
        (rotating_planar(3, 2.0), (0.4, z6, 1e-2 * np.ones(6)), None, None),
    ]
    for model, state, dyne_model, dyne_state in cases:
        lin = spacar.linearize(model, state)
        dyne_model, (t, z0, zd0) = dyne_model or model, dyne_state or state
        zdd0 = np.zeros(len(z0)) if lin.n_line else nominal_accelerations(model, t, z0, zd0)
        R0, Jz, Jzd, Mbar = reduced_residual_jacobian(dyne_model, t, z0, zd0, zdd0)
        K, Cd = lin.stiffness, lin.damping
        scale = np.abs(K).max() + np.abs(Cd).max()
        assert np.abs(Mbar - lin.M0).max() <= 1e-12 * np.abs(Mbar).max()
        assert np.abs(Jz - K).max() <= 1e-7 * scale
        assert np.abs(Jzd - Cd).max() <= 1e-7 * scale
        assert np.abs(-R0 - lin.r0).max() <= 1e-10 * (np.abs(lin.r0).max() + 1e-3)
    assert np.abs(lin.C0).max() > 0.01  # the rotating beam bent: Coriolis terms


def nominal_accelerations(model, t, z0, zd0):
    """q̈ of the degrees of freedom at (t, z0, ż0)."""
    sim = assembled(model.copy())
    sim.move_to(t, z0, zd0)
    return np.array(sim.data.qdd)


def test_line_parameters_along_the_slider_crank_motion():
    """Rigid rod with LINE bending deformations: the nonlinear motion is rigid; at every output
    time (LINE ⇒ linearization) r0 equals the nominal reaction stress σ^ℓ of (6.1) and the
    eigenfrequencies vary with the crank angle. Against the model with DYNE instead of LINE at
    the same state (zero bending, q̈_D its accelerations): M0, K0 and C0 + D0 are the same,
    r0 = M̄ q̈_D (the rigid rod supplies what would accelerate the flexible one) and
    K0 + N0 + G0 differs by the mass-matrix term −(∂M̄/∂z) q̈_D of the nominal z̈ = 0."""
    model = line_slider_crank()
    model.timestep(8, 2.0)
    model.forcemode(2)
    model.epskin(1e-12)
    res = model.run()
    assert len(res.linearizations) == 9
    rows = [res.deformation_index(e, i) for e, i in ((2, 2), (2, 3), (3, 2), (3, 3))]
    assert np.abs(res.e[:, rows]).max() <= 1e-12  # LINE parameters are fixed in the motion
    dyne = spacar.read_string(EXAMPLE.read_text().replace("Timestep 100 5.0", ""))
    dyne.epskin(1e-12)
    sim = assembled(dyne)
    first, zero, h = [], np.zeros(4), 1e-5

    def mbar(t, z):
        sim.move_to(t, z, zero)
        return np.array(sim.data.Mbar)

    for k, lin in enumerate(res.linearizations):
        assert lin.n_line == 4 and [lbl[1:] for lbl in lin.z_labels] == [(2, 2), (2, 3), (3, 2), (3, 3)]
        assert np.allclose(lin.r0, res.sigma[k, rows], rtol=1e-12, atol=1e-15)
        first.append(lin.eigenfrequencies()[0])
        ref = spacar.linearize(dyne, (lin.t, zero, zero))
        for name in ("M0", "K0"):
            assert np.allclose(getattr(lin, name), getattr(ref, name), rtol=1e-12, atol=1e-14), name
        # C0 + D0 vanish here (no damping, no velocity-dependent forces on the rod's bending):
        # both are the round-off of central differences of the residual, 1e-14 to 1.4e-13 (it
        # depends on the rounding of the element code).
        assert np.abs(lin.damping - ref.damping).max() <= 1e-12
        sim.move_to(lin.t, zero, zero)
        Mb, qdd = np.array(sim.data.Mbar), np.array(sim.data.qdd)
        assert np.allclose(lin.r0, Mb @ qdd, rtol=1e-10, atol=1e-14)
        dM_qdd = np.column_stack([(mbar(lin.t, dz) - mbar(lin.t, -dz)) @ qdd / (2 * h) for dz in h * np.eye(4)])
        scale = np.abs(ref.stiffness).max()
        assert np.abs(lin.stiffness - (ref.stiffness - dM_qdd)).max() <= 1e-8 * scale
        if k > 0:  # G0 holds the geometric stiffness of σ^ℓ, the DYNE model's constitutive 0
            assert np.abs(lin.G0 - ref.G0).max() > 1e-6 * scale
    assert np.abs(res.linearizations[0].r0).max() <= 1e-15  # crank along the slide: no bending load
    assert max(first) / min(first) > 1.05
    assert np.abs(res.sigma[1:, rows]).max() > 1e-3


# --------------------------------------------------------------------------------------------
# Linear response against the nonlinear simulation
# --------------------------------------------------------------------------------------------

def response_difference(model_of, lin, labels, y0, T):
    """max |z_nonlinear(t) − z_linear(t)| over t ∈ [0, T], z_linear = (e^{At} y0)_z."""
    m = model_of()
    n = len(labels)
    for j, (_, el, i) in enumerate(labels):
        if y0[j]:
            m.e(el, i, y0[j])
        if y0[n + j]:
            m.ed(el, i, y0[n + j])
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-12)
    m.timestep(10, T)
    res = m.run()
    z_nl = res.e[:, [res.deformation_index(el, i) for (_, el, i) in labels]]
    A = lin.state_matrix()
    z_lin = np.array([(scipy.linalg.expm(A * t) @ y0)[:n] for t in res.t - res.t[0]])
    return np.abs(z_nl - z_lin).max(), np.abs(z_lin).max()


@pytest.mark.parametrize("system", ["rotating beam", "gimbal rotor"])
def test_linear_response_matches_nonlinear_simulation(system):
    """From a disturbed steady state (the rotating PLBEAMNL beam with bending rates, the gimbal
    rotor with a tilt and a tilt rate), over one period of the lowest mode: the difference
    between the nonlinear and the linearized response shrinks like ε² (and the relative
    difference like ε) as the disturbance ε goes down by decades."""
    if system == "rotating beam":
        def model_of():
            return rotating_planar(2, 2.0)
        shape = np.array([0, 0, 0, 0, 1.0, -1.0, 2.0, -2.0])
    else:
        def model_of():
            return gimbal_rotor()
        shape = np.array([1.0, 0.0, 0.0, 1.0])
    lin = spacar.linearize(model_of(), (0.0, np.zeros(len(shape) // 2), np.zeros(len(shape) // 2)))
    T = 2 * np.pi / np.abs(lin.eigenvalues()[0].imag)
    diffs = []
    for eps in (1e-2, 1e-3, 1e-4):
        d, size = response_difference(model_of, lin, lin.z_labels, eps * shape, T)
        diffs.append(d)
        assert d < 1e-2 * size or eps == 1e-2 and d < 0.1 * size
    ratios = np.array(diffs[:-1]) / np.array(diffs[1:])
    assert np.all(ratios > 80), ratios


# --------------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------------

COLUMN = """\
PLBEAMNL 1 1 2 3 4
PLBEAMNL 2 3 4 5 6
X 3 0.5 0.
X 5 1.0 0.
FIX 1
FIX 2
DYNE 1 2 3
DYNE 2 2 3
ESTIFF 1 0. 1.
ESTIFF 2 0. 1.
EMASS 1 1.
EMASS 2 1.
FORCE 5 {load} 0.
LINEAR {mode}
END
"""


def comment_numbers(out, prefix):
    line = next(ln for ln in out.splitlines() if ln.startswith("* " + prefix))
    return np.array([float(v) for v in line.split(":")[-1].split()])


def test_spacar_run_prints_eigenfrequencies_and_buckling_factors(tmp_path, capsys):
    path = tmp_path / "column.dat"
    path.write_text(COLUMN.format(load="0.", mode=1))
    assert main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    f = comment_numbers(out, "eigenfrequencies [Hz]")
    assert np.allclose(2 * np.pi * f[:3], [3.517715, 22.22147, 75.15708], rtol=2e-6)
    assert "buckling" not in out
    path.write_text(COLUMN.format(load="-1.", mode=2))
    assert main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    assert abs(comment_numbers(out, "buckling factors")[0] - 2.4686648) < 1e-5
    assert comment_numbers(out, "eigenfrequencies [Hz]")[0] < 0.56  # softened by the load
    path.write_text(COLUMN.format(load="0.", mode=0))
    assert main(["run", str(path)]) == 0
    assert "eigenfrequencies" not in capsys.readouterr().out


def test_mechanism_without_coordinates_to_linearize(tmp_path, capsys):
    """A rigid driven mechanism (no DOF, no LINE) with LINEAR 2: every result is empty, and
    `spacar run` says so instead of printing empty lists."""
    text = "".join(line for line in EXAMPLE.read_text().splitlines(keepends=True) if not line.startswith("DYNE"))
    text = text.replace("Timestep 100 5.0", "Timestep 2 1.0\nLINEAR 2")
    lin = spacar.linearize(spacar.read_string(text))
    assert lin.M0.shape == (0, 0) and lin.eigenfrequencies().size == 0 and lin.eigenvalues().size == 0
    freq, shapes_z, shapes_x = lin.mode_shapes()
    assert freq.size == 0 and shapes_z.shape == (0, 0) and shapes_x.shape == (lin.DF.shape[0], 0)
    assert lin.buckling_factors().size == 0 and lin.state_space()[0].shape == (0, 0)
    path = tmp_path / "rigid.dat"
    path.write_text(text)
    assert main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    assert "* linearized equations at t = 1: 0 coordinates" in out
    assert "eigenfrequencies" not in out and "buckling" not in out
