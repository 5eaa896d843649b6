"""Element-level verification of the planar elements PLTRUSS, PLBEAM, PLBEAMNL, PLBEAMC, PLHINGE
(issue #3; formulation.md §4.1–4.4, §10.1) through `spacar._testing.element_kernel`.

The generic finite-difference and invariance checks live in support/element_checks.py (one line per
element type below); this module adds closed-form and independent physical references:
deformation formulas of §4, constant curvature, the PLBEAMNL arc expansion, constitutive
matrices and beam-theory strain energy, rigid-bar kinetic energy, the Hermite-interpolated mass
model by quadrature, and the gravity loads of §4.1/§4.2.
"""

import math

import numpy as np
import pytest

from support.element_checks import (  # noqa: F401  (record: fixture used by the generic checks)
    GAUSS_W,
    GAUSS_XI,
    N_CONFIGS,
    ElementCase,
    GenericElementChecks,
    chord,
    hermite,
    orientations_only,
    random_configuration,
    record,
)
from spacar import _testing

PLANAR_CASES = [
    ElementCase("PLTRUSS", chord),
    ElementCase("PLBEAM", chord),
    ElementCase("PLBEAMNL", chord),
    ElementCase("PLBEAMC", chord),
    ElementCase("PLHINGE", orientations_only),
]
CASES = {c.type: c for c in PLANAR_CASES}
BEAMS = ["PLBEAM", "PLBEAMNL"]
WITH_MASS = ["PLTRUSS", "PLBEAM", "PLBEAMNL", "PLBEAMC"]


@pytest.fixture(params=PLANAR_CASES, ids=str)
def case(request):
    return request.param


class TestPlanarElements(GenericElementChecks):
    """B, c, Σσ_iH_i, M, h, gravity against differences; rigid-motion invariance; e(ref) = 0."""


def t(phi):
    return np.array([math.cos(phi), math.sin(phi)])


def n(phi):
    return np.array([-math.sin(phi), math.cos(phi)])


# ---------------------------------------------------------------------------------------------
# Deformations: closed forms of §4
# ---------------------------------------------------------------------------------------------

def closed_form(type_, x, l0, alpha0):
    if type_ == "PLHINGE":
        return np.array([x[1] - x[0]])
    if type_ == "PLTRUSS":
        return np.array([math.hypot(x[2] - x[0], x[3] - x[1]) - l0])
    d = x[3:5] - x[0:2]
    l, alpha = math.hypot(*d), math.atan2(d[1], d[0])
    if type_ == "PLBEAMC":  # the angles, wrapped to (−π, π], and the arc's length
        dp = math.remainder(alpha0 + x[2] - alpha, 2 * math.pi)
        dq = math.remainder(alpha - alpha0 - x[5], 2 * math.pi)
        dm = 0.5 * (dp + dq)
        b = 0.5 * l0 * (dp - dq)
        return np.array([l * (dm / math.sin(dm) if dm else 1.0) - l0 + b * b / (10 * l0), l0 * dp, l0 * dq])
    e2 = l0 * math.sin(alpha0 + x[2] - alpha)  # l0 sin(φp − α)
    e3 = l0 * math.sin(alpha - alpha0 - x[5])  # l0 sin(α − φq)
    e1 = l - l0
    if type_ == "PLBEAMNL":
        e1 += (2 * e2 * e2 + e2 * e3 + 2 * e3 * e3) / (30 * l0)
    return np.array([e1, e2, e3])


@pytest.mark.parametrize("type_", list(CASES))
def test_deformations_match_closed_form(type_):
    c = CASES[type_]
    for _, ref, k, x in c.samples("closed"):
        alpha0 = ref.lgeomy[0] if ref.lgeomy else 0.0
        np.testing.assert_allclose(k.deformations(x), closed_form(type_, x, ref.l0, alpha0),
                                   rtol=0, atol=1e-14 * max(ref.l0, 1.0))


def test_pltruss_convective_term_closed_form():
    """c1 = (v·v − (e_l·v)²)/l, v = ẋ_q − ẋ_p (§4.1)."""
    for rng, _, k, x in CASES["PLTRUSS"].samples("c-closed"):
        xd = rng.normal(size=4)
        d, v = x[2:] - x[:2], xd[2:] - xd[:2]
        l = np.linalg.norm(d)
        np.testing.assert_allclose(k.convective(x, xd), [(v @ v - (d @ v / l) ** 2) / l], rtol=1e-13)


def test_plhinge_derivatives_are_constant():
    for rng, _, k, x in CASES["PLHINGE"].samples("hinge"):
        np.testing.assert_array_equal(k.first_derivatives(x), [[-1.0, 1.0]])
        assert not k.convective(x, rng.normal(size=2)).any()
        assert not k.stress_hessian(x, rng.normal(size=1)).any()


# ---------------------------------------------------------------------------------------------
# Constant curvature and the PLBEAMNL arc
# ---------------------------------------------------------------------------------------------

def arc(p, alpha0, l0, theta):
    """Nodes on a circular arc of length l0 whose chord has angle α0 and end tangents at ∓θ to
    the chord (curvature κ = 2θ/l0, CCW for θ > 0): chord l = (2/κ) sin(κl0/2) = l0 sin θ/θ,
    βp = −θ, βq = +θ (material tangents = arc tangents; reference chord angle α0)."""
    chord_length = l0 * math.sin(theta) / theta if theta != 0 else l0
    q = p + chord_length * t(alpha0)
    return np.array([p[0], p[1], -theta, q[0], q[1], theta])


@pytest.mark.parametrize("type_", BEAMS)
def test_constant_curvature_bending(type_):
    """κ > 0 (CCW): e2 = e3 = −l0 sin(κ l0/2) (§0 table, verified); κ < 0 mirrors it."""
    rng = np.random.default_rng(7)
    for _ in range(N_CONFIGS):
        l0, alpha0, kappa = rng.uniform(0.5, 2), rng.uniform(-math.pi, math.pi), rng.uniform(-2, 2)
        k = _testing.element_kernel(type_, l0=l0, lgeomy=[alpha0])
        e = k.deformations(arc(rng.uniform(-1, 1, 2), alpha0, l0, kappa * l0 / 2))
        expected = -l0 * math.sin(kappa * l0 / 2)
        np.testing.assert_allclose(e[1:], [expected, expected], rtol=0, atol=1e-14)
        if kappa > 0:
            assert e[1] < 0 and e[2] < 0


def test_plbeamc_is_exact_on_a_circular_arc():
    """PLBEAMC on an arc of length l0 turning by 2θ: e2 = e3 = −l0 θ (the angles) and no
    elongation, for any θ up to a half turn; its elongation is PLBEAMNL's to second order."""
    rng = np.random.default_rng(13)
    for _ in range(N_CONFIGS):
        l0, alpha0 = rng.uniform(0.5, 2), rng.uniform(-math.pi, math.pi)
        k = _testing.element_kernel("PLBEAMC", l0=l0, lgeomy=[alpha0])
        for theta in (1e-4, 0.3, -1.2, 3.0):
            e = k.deformations(arc(rng.uniform(-1, 1, 2), alpha0, l0, theta))
            np.testing.assert_allclose(e, [0.0, -l0 * theta, -l0 * theta], rtol=0, atol=2e-15 * l0 / abs(math.sin(theta)))
    nl = _testing.element_kernel("PLBEAMNL", l0=1.0, lgeomy=[0.0])
    arc_beam = _testing.element_kernel("PLBEAMC", l0=1.0, lgeomy=[0.0])
    for s in (1e-2, 5e-3):                                   # a cubic bend, symmetric and antisymmetric parts
        x = np.array([0.0, 0.0, 3 * s, 1.0, 0.1 * s, -s])
        a, b = arc_beam.deformations(x), nl.deformations(x)
        assert abs(a[0] - b[0]) < 2 * s**3


def test_plbeamnl_circular_arc_elongation():
    """Arc of length l0 (inextensible bending): e1 = −(17/360) l0 θ⁴ + O(θ⁶), e2 = e3 = −l0 sin θ
    (§10.1). Exact series: e1/(−17/360 l0 θ⁴) = 1 − (109/714) θ² + O(θ⁴)."""
    rng = np.random.default_rng(11)
    for _ in range(5):
        l0, alpha0 = rng.uniform(0.5, 2), rng.uniform(-math.pi, math.pi)
        k = _testing.element_kernel("PLBEAMNL", l0=l0, lgeomy=[alpha0])
        deviation = {}
        for theta in (0.02, 0.01):
            e = k.deformations(arc(rng.uniform(-1, 1, 2), alpha0, l0, theta))
            np.testing.assert_allclose(e[1:], -l0 * math.sin(theta), rtol=1e-12)
            ratio = e[0] / (-17 / 360 * l0 * theta**4)
            assert abs(ratio - 1) < theta**2  # → 1 as θ → 0
            deviation[theta] = ratio - 1
            # next term of the expansion; residual O(θ⁴) plus round-off of l − l0 (~1e-6 here)
            assert abs(ratio - (1 - 109 / 714 * theta**2)) < 5e-6
        # the deviation is O(θ²): halving θ divides it by ≈ 4
        assert 3.5 < deviation[0.02] / deviation[0.01] < 4.5


def test_plbeam_nonlinear_correction_is_arc_excess():
    """§4.3: e2 = e3 = −l0θ gives the correction l0θ²/6: e1(NL) − e1(linear) at equal x."""
    rng = np.random.default_rng(5)
    for _ in range(N_CONFIGS):
        ref = CASES["PLBEAM"].reference(CASES["PLBEAM"], rng)
        x = random_configuration(rng, CASES["PLBEAM"].kinds, ref)
        lin = _testing.element_kernel("PLBEAM", l0=ref.l0, lgeomy=list(ref.lgeomy)).deformations(x)
        nl = _testing.element_kernel("PLBEAMNL", l0=ref.l0, lgeomy=list(ref.lgeomy)).deformations(x)
        e2, e3 = lin[1:]
        np.testing.assert_allclose(nl[1:], lin[1:], rtol=0, atol=0)
        np.testing.assert_allclose(nl[0] - lin[0], (2 * e2**2 + e2 * e3 + 2 * e3**2) / (30 * ref.l0),
                                   rtol=1e-12, atol=1e-15)


# ---------------------------------------------------------------------------------------------
# Constitutive matrices and strain energy
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("type_", list(CASES))
def test_constitutive_matrix(type_):
    rng = np.random.default_rng(3)
    for _ in range(5):
        l0, a, b = rng.uniform(0.5, 2), rng.uniform(1, 1e4), rng.uniform(1, 1e2)
        k = _testing.element_kernel(type_, l0=l0)
        if type_ in BEAMS or type_ == "PLBEAMC":  # ESTIFF EA EI
            expected = np.zeros((3, 3))
            expected[0, 0] = a / l0
            expected[1:, 1:] = b / l0**3 * np.array([[4.0, -2.0], [-2.0, 4.0]])
            values = [a, b]
        elif type_ == "PLTRUSS":  # ESTIFF EA
            expected, values = np.array([[a / l0]]), [a]
        else:  # PLHINGE: ESTIFF St
            expected, values = np.array([[a]]), [a]
        np.testing.assert_allclose(k.constitutive(values), expected, rtol=1e-15, atol=0)
        assert not k.constitutive([]).any()


@pytest.mark.parametrize("type_", BEAMS)
def test_bending_strain_energy_of_constant_curvature(type_):
    """½eᵀSe → ½ EI κ² l0 (beam theory) as κ → 0. PLBEAM: ratio = sin²θ/θ² + EA-term
    = 1 − θ²/3 + (EA l0²/EI) θ²/144 + O(θ⁴), θ = κ l0/2."""
    rng = np.random.default_rng(13)
    for _ in range(5):
        l0, alpha0 = rng.uniform(0.5, 2), rng.uniform(-math.pi, math.pi)
        EI = rng.uniform(1, 10)
        EA = EI * rng.uniform(10, 1000) / l0**2
        k = _testing.element_kernel(type_, l0=l0, lgeomy=[alpha0])
        S = k.constitutive([EA, EI])
        for kappa in (1e-2, 1e-3, 1e-4):
            theta = kappa * l0 / 2
            e = k.deformations(arc(rng.uniform(-1, 1, 2), alpha0, l0, theta))
            ratio = 0.5 * e @ S @ e / (0.5 * EI * kappa**2 * l0)
            bound = (1 / 3 + EA * l0**2 / (144 * EI)) * theta**2 * 1.01 + 1e-9
            assert abs(ratio - 1) < bound


# ---------------------------------------------------------------------------------------------
# Mass and gravity: independent references
# ---------------------------------------------------------------------------------------------

def straight_rigid(type_, rng):
    """A straight unstrained element of length l0 at a random place and angle, moving rigidly
    with centre velocity u and angular velocity ω: kernel, x, ẋ, m, l0, u, ω."""
    l0, alpha0, rhoA = rng.uniform(0.5, 2), rng.uniform(-math.pi, math.pi), rng.uniform(0.5, 3)
    alpha = rng.uniform(-math.pi, math.pi)
    c, u, omega = rng.uniform(-2, 2, 2), rng.normal(size=2), rng.normal()
    rp, rq = -0.5 * l0 * t(alpha), 0.5 * l0 * t(alpha)

    def vel(r):  # u + ω k × r
        return u + omega * np.array([-r[1], r[0]])

    if type_ == "PLTRUSS":
        k = _testing.element_kernel(type_, l0=l0, emass=[rhoA])
        x = np.concatenate([c + rp, c + rq])
        xd = np.concatenate([vel(rp), vel(rq)])
    else:  # material tangents along the chord: φ = α0 + β = α, β̇ = ω
        k = _testing.element_kernel(type_, l0=l0, lgeomy=[alpha0], emass=[rhoA])
        beta = alpha - alpha0
        x = np.concatenate([c + rp, [beta], c + rq, [beta]])
        xd = np.concatenate([vel(rp), [omega], vel(rq), [omega]])
    return k, x, xd, rhoA * l0, l0, u, omega


@pytest.mark.parametrize("type_", WITH_MASS)
def test_rigid_bar_kinetic_energy(type_):
    """T = ½ m|u|² + ½ (m l0²/12) ω² for a rigid straight element (§4.1, §4.2)."""
    rng = np.random.default_rng(17)
    for _ in range(N_CONFIGS):
        k, x, xd, m, l0, u, omega = straight_rigid(type_, rng)
        np.testing.assert_allclose(k.deformations(x), 0.0, atol=1e-14)
        expected = 0.5 * m * u @ u + 0.5 * m * l0**2 / 12 * omega**2
        np.testing.assert_allclose(k.kinetic_energy(x, xd), expected, rtol=1e-13)
        M, _ = k.mass(x, xd)
        np.testing.assert_allclose(0.5 * xd @ M @ xd, expected, rtol=1e-13)


def test_pltruss_consistent_mass_matrix():
    """M_e = (ρA l0/6)[[2I, I], [I, 2I]], h_e = 0 (§4.1)."""
    for rng, ref, k, x in CASES["PLTRUSS"].samples("M-closed"):
        M, h = k.mass(x, rng.normal(size=4))
        I2 = np.eye(2)
        np.testing.assert_allclose(M, ref.emass[0] * ref.l0 / 6 * np.block([[2 * I2, I2], [I2, 2 * I2]]),
                                   rtol=1e-14)
        assert not h.any()


@pytest.mark.parametrize("type_", BEAMS)
def test_plbeam_mass_model_by_quadrature(type_):
    """T = ½ρA l0 ∫|ṙ|² dξ and V = −ρA l0 ∫ g·r dξ for r(ξ) = H1 x_p + H2 l0 t_p + H3 x_q + H4 l0 t_q
    (§4.2), integrated by Gauss quadrature; h_e = ρA l0 ∫ Nᵀ a_r dξ with
    a_r = −l0 (H2 β̇p² t_p + H4 β̇q² t_q) — independent of the coded Hermite mass matrix."""
    c = CASES[type_]
    for rng, ref, k, x in c.samples("hermite"):
        xd, g = rng.normal(size=6), rng.normal(size=3) * 10
        rhoA, l0, alpha0 = ref.emass[0], ref.l0, ref.lgeomy[0]
        php, phq = alpha0 + x[2], alpha0 + x[5]
        T = V = 0.0
        h = np.zeros(6)
        for xi, w in zip(GAUSS_XI, GAUSS_W):
            H = hermite(xi)
            r = H[0] * x[0:2] + H[1] * l0 * t(php) + H[2] * x[3:5] + H[3] * l0 * t(phq)
            N = np.zeros((2, 6))
            N[:, 0:2] = H[0] * np.eye(2)
            N[:, 2] = H[1] * l0 * n(php)
            N[:, 3:5] = H[2] * np.eye(2)
            N[:, 5] = H[3] * l0 * n(phq)
            rd = N @ xd
            a_r = -l0 * (H[1] * xd[2] ** 2 * t(php) + H[3] * xd[5] ** 2 * t(phq))
            T += 0.5 * rhoA * l0 * w * rd @ rd
            V -= rhoA * l0 * w * g[:2] @ r
            h += rhoA * l0 * w * N.T @ a_r
        np.testing.assert_allclose(k.kinetic_energy(x, xd), T, rtol=1e-13)
        np.testing.assert_allclose(k.gravity_potential(x, g), V, rtol=1e-12, atol=1e-12 * abs(V) + 1e-13)
        np.testing.assert_allclose(k.mass(x, xd)[1], h, rtol=0, atol=1e-13 * max(np.abs(h).max(), 1))


@pytest.mark.parametrize("type_", WITH_MASS)
def test_gravity_loads(type_):
    """Total force m g on the position nodes (½ m g each); PLBEAM moments ±(ρA l0²/12) n·g on
    βp, βq (§4.1, §4.2). The z component of g is ignored by planar elements."""
    c = CASES[type_]
    for rng, ref, k, x in c.samples("gravity-closed"):
        g = rng.normal(size=3) * 10
        rhoA, l0 = ref.emass[0], ref.l0
        m = rhoA * l0
        f = k.gravity(x, g)
        pos = [0, 1, 2, 3] if type_ == "PLTRUSS" else [0, 1, 3, 4]
        np.testing.assert_allclose(f[pos], 0.5 * m * np.tile(g[:2], 2), rtol=1e-14)
        np.testing.assert_allclose(f[pos[:2]] + f[pos[2:]], m * g[:2], rtol=1e-14)
        if type_ != "PLTRUSS":
            alpha0 = ref.lgeomy[0]
            moment = rhoA * l0**2 / 12
            np.testing.assert_allclose(f[[2, 5]], [moment * n(alpha0 + x[2]) @ g[:2],
                                                   -moment * n(alpha0 + x[5]) @ g[:2]],
                                       rtol=1e-13, atol=1e-14 * moment * 10)


def test_element_checks_finite_differences_are_accurate():
    """The difference helpers themselves reach the accuracy the checks rely on (known
    derivatives of a smooth non-polynomial function)."""
    from support.element_checks import (hessian_fd, jacobian_fd, rel_err, second_directional_fd,
                                STEP_FIRST, STEP_SECOND)

    def f(x):
        return np.array([math.sin(x[0]) * math.exp(x[1]), 1 / math.hypot(x[0], x[1] + 2)])

    x, v = np.array([0.3, -0.4]), np.array([0.7, -1.1])
    J = np.array([[math.cos(x[0]) * math.exp(x[1]), math.sin(x[0]) * math.exp(x[1])],
                  [-x[0] / math.hypot(x[0], x[1] + 2) ** 3, -(x[1] + 2) / math.hypot(x[0], x[1] + 2) ** 3]])
    assert rel_err(J, jacobian_fd(f, x, np.full(2, STEP_FIRST))) < 1e-11
    H0 = np.array([[-math.sin(x[0]), math.cos(x[0])], [math.cos(x[0]), math.sin(x[0])]]) * math.exp(x[1])
    assert rel_err(H0, hessian_fd(lambda y: f(y)[0], x, np.full(2, STEP_SECOND))) < 1e-9
    assert rel_err(v @ H0 @ v, second_directional_fd(lambda y: f(y)[0], x, v, STEP_SECOND)) < 1e-9


def test_element_checks_rigid_motion_of_euler_parameters():
    """Helper for spatial elements: R(q ⊗ λ) = R(q) R(λ), R orthogonal for unit λ."""
    from support.element_checks import quat_mul, random_unit_quaternion, rotation_matrix

    rng = np.random.default_rng(1)
    for _ in range(5):
        q, lam = random_unit_quaternion(rng), random_unit_quaternion(rng)
        np.testing.assert_allclose(rotation_matrix(quat_mul(q, lam)), rotation_matrix(q) @ rotation_matrix(lam),
                                   atol=1e-14)
        np.testing.assert_allclose(rotation_matrix(q) @ rotation_matrix(q).T, np.eye(3), atol=1e-14)


# ---------------------------------------------------------------------------------------------
# The closed-form inverse of the beams (the explicit chain's positions, chain.hpp)
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("type_", BEAMS)
@pytest.mark.parametrize("end", [0, 1])
def test_beam_end_from_the_other_end_and_its_deformations(type_, end):
    # From a random configuration (beams bent by more than 90° too): the solved end reproduces e
    # exactly, the other end is kept, and from a guess near the configuration (angles a turn
    # away too) it is the configuration itself: the branch of the arcsines and the turn of the
    # rotation are the guess's.
    c = CASES[type_]
    solved = slice(3, 6) if end == 1 else slice(0, 3)
    kept = slice(0, 3) if end == 1 else slice(3, 6)
    checked = 0
    for rng, ref, k, x in c.samples("solve_end"):
        assert k.has_closed_form
        e = k.deformations(x)
        alpha0 = ref.lgeomy[0] if ref.lgeomy else 0.0
        alpha = math.atan2(x[4] - x[1], x[3] - x[0])
        if min(abs(math.cos(alpha0 + x[2] - alpha)), abs(math.cos(alpha - alpha0 - x[5]))) < 0.2:
            continue  # a bend near 90°: a guess 0.05 away may lie on the other branch
        turn = 2 * math.pi * rng.integers(-2, 3)
        guess, expected = x.copy(), x.copy()
        guess[solved] += np.append(rng.normal(scale=0.01 * ref.l0, size=2), rng.normal(scale=0.01) + turn)
        expected[solved.stop - 1] += turn
        y = k.solve_end(end, e, guess, guess)
        np.testing.assert_array_equal(y[kept], x[kept])
        np.testing.assert_allclose(k.deformations(y), e, rtol=0, atol=1e-13 * ref.l0)
        np.testing.assert_allclose(y, expected, rtol=0, atol=1e-12 * max(ref.l0, 1.0))
        checked += 1
    assert checked >= 5


@pytest.mark.parametrize("type_", BEAMS)
def test_beam_end_outside_the_range_of_its_deformations_is_declined(type_):
    c = CASES[type_]
    for _, ref, k, x in c.samples("solve_end range", n=3):
        for e in ([-2 * ref.l0, 0.0, 0.0], [0.0, 1.5 * ref.l0, 0.0], [0.0, 0.0, -1.01 * ref.l0]):
            assert k.solve_end(1, np.array(e), x, x) is None
    assert not any(_testing.element_kernel(t).has_closed_form for t in ("PLTRUSS", "PLHINGE"))


@pytest.mark.parametrize("type_", BEAMS)
def test_beam_end_follows_its_known_end_with_the_guess_branches(type_):
    # The known end turned and moved rigidly since the guess (as the blocks before it in a chain):
    # the solved end turns and moves with it, bent as the guess on each branch.
    c = CASES[type_]
    for rng, ref, k, x in c.samples("solve_end rigid"):
        e = k.deformations(x)
        angle, shift = rng.uniform(-4.0, 4.0), rng.normal(size=2)  # turned by more than π too
        rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
        moved = x.copy()
        moved[0:2] = rot @ x[0:2] + shift
        moved[3:5] = rot @ x[3:5] + shift
        moved[[2, 5]] += angle
        start = moved.copy()
        start[3:6] = x[3:6]  # the solved end still where the guess has it
        y = k.solve_end(1, e, x, start)
        np.testing.assert_allclose(y, moved, rtol=0, atol=1e-12 * max(ref.l0, 1.0) * (1 + np.abs(x).max()))
