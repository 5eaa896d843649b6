"""Element-level verification of the spatial elements TRUSS, BEAM, BEAMNL, HINGE, L2MIN1
(issue #4; formulation.md §0, §4.1, §4.8–4.10, §4.13, §10.1) through `spacar._testing.element_kernel`.

The generic finite-difference and invariance checks live in support/element_checks.py (one line per
case below; for element types with LAMBDA nodes the derivative checks run at unit Euler
parameters and again off the unit sphere, where R(λ) is the quadratic form of §0). This module
adds closed forms and independent references: the deformation formulas of §4 evaluated with
R(λ) in numpy, the BEAM/BEAMNL planar reduction to PLBEAM/PLBEAMNL (deformations, B, T, M, h,
gravity), the bending-pair and torsion sign conventions, constitutive matrices and beam-theory
strain energies, the rigid-rod kinetic energy with and without rotary inertia, the Hermite mass
model by Gauss quadrature, the HINGE angle range, frame rule, misalignment signs and regularity
at a half turn, and the exact L2MIN1 and TRUSS forms.
"""

import math

import numpy as np
import pytest

from support.element_checks import (  # noqa: F401  (record: fixture used by the generic checks)
    GAUSS_W,
    GAUSS_XI,
    N_CONFIGS,
    OFF_SPHERE_NORMS,
    ElementCase,
    GenericElementChecks,
    Reference,
    assemble,
    chord,
    hermite,
    jacobian_fd,
    orientations_only,
    quat_mul,
    random_unit_quaternion,
    record,
    rel_err,
    rotation_matrix,
    skew,
    wrap_to_pi,
)
from support.spatial_models import E_ as E_of, G_ as G_of, hinge_frame, unit
from spacar import _core, _testing

TOL = 1e-14  # closed forms: round-off of a few operations on O(1) numbers


def section_frame(rng, ex):
    """C0 = [e_x0 e_y0 e_z0]: e_x0 = ex, e_y0 a random unit vector ⟂ e_x0, e_z0 = e_x0 × e_y0."""
    y = rng.normal(size=3)
    y = unit(y - (y @ ex) * ex)
    return np.column_stack([ex, y, np.cross(ex, y)])


def lgeomy_of(C0):
    """BEAM LGEOMY: the 9 numbers e_x0, e_y0, e_z0 (the columns of C0)."""
    return tuple(C0.T.ravel())


def beam(rotary=False, warping=False):
    """Random reference of a BEAM(NL): chord of length l0 ∈ [0.5, 2] in a random direction, random
    cross-section frame, ρA ∈ [0.5, 3]; rotary: EMASS ρA ρIp ρIy ρIz with ρIy, ρIz = ρA (radius of
    gyration 0.07…0.3 l0)², ρIp = ρIy + ρIz; warping (BEAMW): ρIw = ρIy ρIz / ρA as well."""
    def reference(case, rng):
        l0 = rng.uniform(0.5, 2.0)
        p = rng.uniform(-2.0, 2.0, size=3)
        d = unit(rng.normal(size=3))
        C0 = section_frame(rng, d)
        rhoA = rng.uniform(0.5, 3.0)
        emass = (rhoA,)
        if rotary:
            Iy, Iz = rhoA * (rng.uniform(0.07, 0.3, size=2) * l0) ** 2
            emass = (rhoA, Iy + Iz, Iy, Iz) + ((Iy * Iz / rhoA,) if warping else ())
        return Reference(x=assemble(case.kinds, [p, p + l0 * d]), l0=l0, lgeomy=lgeomy_of(C0),
                         emass=emass, scale=l0)
    return reference


# Axes for the hinge: coordinate axes, ties of the smallest component (→ the first one),
# oblique and unnormalised axes; random ones are drawn as well.
SPECIAL_AXES = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1), (0.3, -0.3, 2), (2, 0.5, -0.5), (1, 1, 0),
                (0, -1, 1), (1, 0, 1), (-2, 0.5, 1), (0, 0, -3.7), (1e-3, 5, -2)]


def hinge_axis(case, rng):
    """HINGE reference: both orientations at the reference, a special or random axis."""
    i = rng.integers(0, 2 * len(SPECIAL_AXES))
    axis = np.array(SPECIAL_AXES[i], float) if i < len(SPECIAL_AXES) else rng.normal(size=3) * rng.uniform(0.2, 5)
    return Reference(x=assemble(case.kinds, []), params=tuple(axis))


SPATIAL_CASES = [
    ElementCase("TRUSS", chord),
    ElementCase("BEAM", beam()),
    ElementCase("BEAM", beam(rotary=True), label="BEAM+rotary"),
    ElementCase("BEAMNL", beam()),
    ElementCase("BEAMNL", beam(rotary=True), label="BEAMNL+rotary"),
    ElementCase("BEAMC", beam(), max_rotation=1.0),
    ElementCase("BEAMW", beam(rotary=True, warping=True), label="BEAMW+rotary"),
    ElementCase("BEAMC", beam(rotary=True), label="BEAMC+rotary", max_rotation=1.0),
    ElementCase("HINGE", hinge_axis, angles=(0,)),
    ElementCase("L2MIN1", orientations_only),
]
CASES = {str(c): c for c in SPATIAL_CASES}
BEAMS = ["BEAM", "BEAMNL", "BEAMC"]


@pytest.fixture(params=SPATIAL_CASES, ids=str)
def case(request):
    return request.param


class TestSpatialElements(GenericElementChecks):
    """B, c, Σσ_iH_i, M, h, gravity against differences (unit and non-unit λ); rigid-motion
    invariance (HINGE e1 modulo 2π); e(ref) = 0."""


def samples_on_and_off_sphere(case, check):
    yield from case.samples(check)
    yield from case.samples(check, off_sphere=True)


# ---------------------------------------------------------------------------------------------
# Euler-parameter matrices of §0 (independent numpy versions)
# ---------------------------------------------------------------------------------------------

def T_of(l, c):
    """T_c(λ) = ∂(R(λ)c)/∂λ = 2 [λ0 c + λ̄×c | (λ̄·c)I + λ̄cᵀ − cλ̄ᵀ − λ0 c~] (§0)."""
    l0, lb = l[0], np.asarray(l[1:4])
    return 2.0 * np.column_stack([l0 * c + np.cross(lb, c),
                                  (lb @ c) * np.eye(3) + np.outer(lb, c) - np.outer(c, lb) - l0 * skew(c)])


def axis_angle(axis, angle):
    """Unit Euler parameters of a rotation by `angle` about `axis` (right-hand)."""
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * unit(axis)])


def test_euler_parameter_helpers():
    """The numpy E, G, T_c against the identities of §0: R = E Gᵀ, T_c = ∂(Rc)/∂λ (also off the
    unit sphere), E λ = G λ = 0, E Eᵀ = |λ|² I, R(axis_angle) rotates right-handedly."""
    rng = np.random.default_rng(2)
    for _ in range(5):
        lam = random_unit_quaternion(rng) * rng.uniform(*OFF_SPHERE_NORMS)
        c = rng.normal(size=3)
        np.testing.assert_allclose(E_of(lam) @ G_of(lam).T, rotation_matrix(lam), atol=1e-14)
        np.testing.assert_allclose(T_of(lam, c), jacobian_fd(lambda y: rotation_matrix(y) @ c, lam, np.full(4, 1e-3)),
                                   atol=1e-11)
        np.testing.assert_allclose([E_of(lam) @ lam, G_of(lam) @ lam], 0.0, atol=1e-15)
        np.testing.assert_allclose(E_of(lam) @ E_of(lam).T, (lam @ lam) * np.eye(3), atol=1e-14)
    np.testing.assert_allclose(rotation_matrix(axis_angle([0, 0, 1], 0.3)) @ [1, 0, 0],
                               [math.cos(0.3), math.sin(0.3), 0], atol=1e-15)


# ---------------------------------------------------------------------------------------------
# Deformations: closed forms of §4 with R(λ) as the quadratic form (unit and non-unit λ)
# ---------------------------------------------------------------------------------------------

def beam_closed_form(x, l0, C0, nonlinear):
    d = x[7:10] - x[0:3]
    l = np.linalg.norm(d)
    el = d / l
    Tp, Tq = rotation_matrix(x[3:7]) @ C0, rotation_matrix(x[10:14]) @ C0  # columns e_x, e_y, e_z
    e = np.array([l - l0,
                  l0 * (Tp[:, 2] @ Tq[:, 1] - Tp[:, 1] @ Tq[:, 2]) / 2,
                  l0 * el @ Tp[:, 2], -l0 * el @ Tq[:, 2],
                  -l0 * el @ Tp[:, 1], l0 * el @ Tq[:, 1]])
    if nonlinear:
        e3, e4, e5, e6 = e[2:]
        e[0] += (2 * e3**2 + e3 * e4 + 2 * e4**2 + 2 * e5**2 + e5 * e6 + 2 * e6**2) / (30 * l0)
    return e


def beamc_closed_form(x, l0, C0):
    """BEAMC (formulation.md): the relative rotation vector φ of the material frames (SciPy's
    log map), the chord c in the mid frame, the unit helix's chord g = G(φ) e_x and the rotation
    β from g to c; the Euler parameters normalized."""
    from scipy.spatial.transform import Rotation

    unit_frame = lambda lam: rotation_matrix(lam / np.linalg.norm(lam)) @ C0  # noqa: E731
    Mp, Mq = unit_frame(x[3:7]), unit_frame(x[10:14])
    phi = Rotation.from_matrix(Mp.T @ Mq).as_rotvec()
    c = (Mp @ Rotation.from_rotvec(phi / 2).as_matrix()).T @ (x[7:10] - x[0:3])
    a = np.linalg.norm(phi)
    s1 = 2 * math.sin(a / 2) / a if a > 1e-4 else 1 - a**2 / 24
    s2 = (1 - s1) / a**2 if a > 1e-4 else 1 / 24
    g = s1 * np.array([1.0, 0.0, 0.0]) + s2 * phi * phi[0]
    axis = np.cross(g, c)
    beta = axis / np.linalg.norm(axis) * math.atan2(np.linalg.norm(axis), g @ c)
    return np.array([np.linalg.norm(c) / np.linalg.norm(g) - l0 + l0 * (beta[1]**2 + beta[2]**2) / 10,
                     l0 * phi[0], l0 * (-phi[1] / 2 - beta[1]), l0 * (-phi[1] / 2 + beta[1]),
                     l0 * (-phi[2] / 2 - beta[2]), l0 * (-phi[2] / 2 + beta[2])])


def hinge_closed_form(x, axis):
    C0 = hinge_frame(axis)
    Rh = C0.T @ rotation_matrix(x[0:4]).T @ rotation_matrix(x[4:8]) @ C0
    return np.array([math.atan2((Rh[2, 1] - Rh[1, 2]) / 2, (Rh[1, 1] + Rh[2, 2]) / 2), Rh[0, 2], -Rh[0, 1]])


def closed_form(type_, x, ref):
    if type_ == "TRUSS":
        return np.array([np.linalg.norm(x[3:6] - x[0:3]) - ref.l0])
    if type_ == "L2MIN1":
        return np.array([x @ x - 1.0])
    if type_ == "HINGE":
        return hinge_closed_form(x, ref.params)
    C0 = np.reshape(ref.lgeomy, (3, 3)).T
    if type_ == "BEAMC":
        return beamc_closed_form(x, ref.l0, C0)
    if type_ == "BEAMW":  # BEAM's, and the end rates of twist against the mean one
        e = beam_closed_form(x[:14], ref.l0, C0, False)
        return np.r_[e, ref.l0**2 * x[14] - e[1], e[1] - ref.l0**2 * x[15]]
    return beam_closed_form(x, ref.l0, C0, type_ == "BEAMNL")


@pytest.mark.parametrize("label", list(CASES))
def test_deformations_match_closed_form(label):
    c = CASES[label]
    for _, ref, k, x in samples_on_and_off_sphere(c, "closed"):
        d = k.deformations(x) - closed_form(c.type, x, ref)
        d[list(c.angles)] = wrap_to_pi(d[list(c.angles)])
        assert np.max(np.abs(d)) < 2 * TOL * max(ref.l0, 1.0)


def test_beamnl_correction():
    """BEAMNL = BEAM except e1 += (2e3² + e3e4 + 2e4² + 2e5² + e5e6 + 2e6²)/(30 l0) (§4.9)."""
    c = CASES["BEAM"]
    for _, ref, k, x in samples_on_and_off_sphere(c, "nl"):
        lin = k.deformations(x)
        nl = _testing.element_kernel("BEAMNL", l0=ref.l0, lgeomy=list(ref.lgeomy)).deformations(x)
        e3, e4, e5, e6 = lin[2:]
        np.testing.assert_array_equal(nl[1:], lin[1:])
        np.testing.assert_allclose(nl[0] - lin[0], (2 * e3**2 + e3 * e4 + 2 * e4**2 + 2 * e5**2 + e5 * e6
                                                    + 2 * e6**2) / (30 * ref.l0), rtol=1e-12, atol=1e-15)


# ---------------------------------------------------------------------------------------------
# BEAM: planar reduction (§10.1)
# ---------------------------------------------------------------------------------------------

def planar_lambda(beta):
    return np.array([math.cos(beta / 2), 0.0, 0.0, math.sin(beta / 2)])


def embed_planar(xp):
    """Planar configuration (xp, yp, βp, xq, yq, βq) → BEAM coordinates x (z = 0, λ = rotation
    about z by β) and J = ∂x/∂x_planar."""
    x = np.concatenate([[xp[0], xp[1], 0.0], planar_lambda(xp[2]), [xp[3], xp[4], 0.0], planar_lambda(xp[5])])
    J = np.zeros((14, 6))
    J[0, 0] = J[1, 1] = J[7, 3] = J[8, 4] = 1.0
    for col, row, beta in ((2, 3, xp[2]), (5, 10, xp[5])):
        J[row:row + 4, col] = [-math.sin(beta / 2) / 2, 0, 0, math.cos(beta / 2) / 2]
    return x, J


def planar_beam_pair(type_, rng):
    """BEAM(NL) with e_x0 = t(α0), e_y0 = n(α0), e_z0 = z and the PLBEAM(NL) with LGEOMY α0."""
    l0, alpha0, rhoA = rng.uniform(0.5, 2), rng.uniform(-math.pi, math.pi), rng.uniform(0.5, 3)
    C0 = np.array([[math.cos(alpha0), -math.sin(alpha0), 0], [math.sin(alpha0), math.cos(alpha0), 0], [0, 0, 1]])
    k3 = _testing.element_kernel(type_, l0=l0, lgeomy=list(lgeomy_of(C0)), emass=[rhoA])
    k2 = _testing.element_kernel("PL" + type_, l0=l0, lgeomy=[alpha0], emass=[rhoA])
    p = rng.uniform(-2, 2, 2)
    xp = np.array([*p, 0.0, *(p + l0 * np.array([math.cos(alpha0), math.sin(alpha0)])), 0.0])
    xp[[0, 1, 3, 4]] += rng.uniform(-0.2, 0.2, 4) * l0
    # BEAMC's angles are those of PLBEAMC below a half turn of the ends (where the relative rotation
    # of the spatial frames wraps); the others: any rotations.
    turn = 1.2 if type_ == "BEAMC" else math.pi
    xp[[2, 5]] = rng.uniform(-turn, turn, 2)
    return k3, k2, xp, l0


@pytest.mark.parametrize("type_", BEAMS)
def test_planar_reduction(type_):
    """Planar configurations: BEAM e1, e5, e6 = PLBEAM e1, e2, e3 and e2 = e3 = e4 = 0 (BEAMNL:
    e1 = PLBEAMNL e1); B J = B_planar; T, M, h, gravity of the planar motion agree (T(x(q), J q̇)
    = T_planar ⇒ JᵀMJ = M_planar and Jᵀ(M J̇q̇ + h) = h_planar by Lagrange)."""
    rng = np.random.default_rng(19)
    for _ in range(N_CONFIGS):
        k3, k2, xp, l0 = planar_beam_pair(type_, rng)
        x, J = embed_planar(xp)
        e3, e2 = k3.deformations(x), k2.deformations(xp)
        np.testing.assert_allclose(e3[[0, 4, 5]], e2, rtol=0, atol=TOL * l0)
        np.testing.assert_allclose(e3[1:4], 0.0, rtol=0, atol=TOL * l0)
        B3, B2 = k3.first_derivatives(x) @ J, k2.first_derivatives(xp)
        np.testing.assert_allclose(B3[[0, 4, 5]], B2, rtol=0, atol=TOL * 10 * l0)
        np.testing.assert_allclose(B3[1:4], 0.0, rtol=0, atol=TOL * 10 * l0)

        vp = rng.normal(size=6)
        v = J @ vp
        T2 = k2.kinetic_energy(xp, vp)
        np.testing.assert_allclose(k3.kinetic_energy(x, v), T2, rtol=1e-13)
        M3, h3 = k3.mass(x, v)
        M2, h2 = k2.mass(xp, vp)
        np.testing.assert_allclose(J.T @ M3 @ J, M2, rtol=0, atol=1e-13 * np.abs(M2).max())
        Jdot_v = np.zeros(14)  # d²λ/dβ² β̇² = −λ β̇²/4
        Jdot_v[3:7] = -planar_lambda(xp[2]) * vp[2] ** 2 / 4
        Jdot_v[10:14] = -planar_lambda(xp[5]) * vp[5] ** 2 / 4
        np.testing.assert_allclose(J.T @ (M3 @ Jdot_v + h3), h2, rtol=0, atol=1e-13 * max(np.abs(h2).max(), 1))

        g = rng.normal(size=3) * 10
        np.testing.assert_allclose(J.T @ k3.gravity(x, g), k2.gravity(xp, g), rtol=0, atol=1e-13 * 10 * l0**2 * 3)
        g[2] = 0.0  # V of the plane (PLBEAM ignores gz; BEAM: gz·z = 0 on the plane anyway)
        np.testing.assert_allclose(k3.gravity_potential(x, g), k2.gravity_potential(xp, g), rtol=1e-13, atol=1e-13)


def test_planar_reduction_with_flipped_section_axis():
    """e_y0 = −n(α0) (so e_z0 = −z) flips e5, e6 relative to PLBEAM (§4.8)."""
    rng = np.random.default_rng(23)
    for _ in range(N_CONFIGS):
        l0, alpha0 = rng.uniform(0.5, 2), rng.uniform(-math.pi, math.pi)
        t0, n0 = np.array([math.cos(alpha0), math.sin(alpha0), 0]), np.array([-math.sin(alpha0), math.cos(alpha0), 0])
        C0 = np.column_stack([t0, -n0, [0, 0, -1]])  # = [t0, −n0, t0 × (−n0)]
        k3 = _testing.element_kernel("BEAM", l0=l0, lgeomy=list(lgeomy_of(C0)))
        k2 = _testing.element_kernel("PLBEAM", l0=l0, lgeomy=[alpha0])
        xp = np.concatenate([[0, 0], rng.uniform(-math.pi, math.pi, 1), l0 * t0[:2] + rng.uniform(-0.2, 0.2, 2) * l0,
                             rng.uniform(-math.pi, math.pi, 1)])
        x, _ = embed_planar(xp)
        e3, e2 = k3.deformations(x), k2.deformations(xp)
        np.testing.assert_allclose(e3[[0, 4, 5]], e2 * [1, -1, -1], rtol=0, atol=TOL * l0)
        np.testing.assert_allclose(e3[1:4], 0.0, rtol=0, atol=TOL * l0)


# ---------------------------------------------------------------------------------------------
# BEAM: bending-pair and torsion signs, constant curvature, strain energy
# ---------------------------------------------------------------------------------------------

def straight_beam(type_, rng):
    """Kernel of a straight BEAM(NL) with a random reference (chord, section frame C0, l0), the
    reference positions x_p, x_q and C0."""
    l0 = rng.uniform(0.5, 2)
    C0 = section_frame(rng, unit(rng.normal(size=3)))
    p = rng.uniform(-2, 2, 3)
    k = _testing.element_kernel(type_, l0=l0, lgeomy=list(lgeomy_of(C0)))
    return k, l0, C0, p


def configuration(p_local, q_local, lam_p, lam_q, p0, C0, rigid=None):
    """BEAM coordinates from node positions in the element frame (origin p0, axes C0) and node
    Euler parameters; optionally followed by the rigid motion (Q = R(qr), translation s)."""
    xp, xq = p0 + C0 @ p_local, p0 + C0 @ q_local
    if rigid is not None:
        qr, s = rigid
        Q = rotation_matrix(qr)
        xp, xq, lam_p, lam_q = Q @ xp + s, Q @ xq + s, quat_mul(qr, lam_p), quat_mul(qr, lam_q)
    return np.concatenate([xp, lam_p, xq, lam_q])


def random_rigid(rng):
    return random_unit_quaternion(rng), rng.uniform(-3, 3, 3)


IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("type_", BEAMS)
def test_bending_pair_and_torsion_signs(type_):
    """Straight reference, one end rotated by θ about a local axis (relative to the chord):
    about y: p → e3 = +l0 sin θ, q → e4 = −l0 sin θ; about z: p → e5 = +l0 sin θ, q → e6 = −l0 sin θ
    (each pair = (l0 sin θp, −l0 sin θq), §4.8); about x (twist ψ of q relative to p): e2 = l0 sin ψ.
    Everything else 0 (BEAMNL: e1 = the bending correction). BEAMC: the angles l0 θ, l0 ψ, and
    e1 the stretch of the arc whose end tangents turn by θ over the chord l0, l0 θ/(2 sin(θ/2)) − l0,
    with its antisymmetric bending θ/2: + l0 θ²/40."""
    rng = np.random.default_rng(29)
    for _ in range(N_CONFIGS):
        k, l0, C0, p0 = straight_beam(type_, rng)
        theta = rng.uniform(-1.5, 1.5)
        rigid = random_rigid(rng)
        for axis, node, index, sign in ((1, "p", 2, +1), (1, "q", 3, -1), (2, "p", 4, +1), (2, "q", 5, -1),
                                        (0, "q", 1, +1), (0, "p", 1, -1)):
            rot = axis_angle(C0[:, axis], theta)
            lam_p, lam_q = (rot, IDENTITY) if node == "p" else (IDENTITY, rot)
            x = configuration(np.zeros(3), [l0, 0, 0], lam_p, lam_q, p0, C0, rigid)
            expected = np.zeros(6)
            expected[index] = sign * l0 * (theta if type_ == "BEAMC" else math.sin(theta))
            if type_ == "BEAMNL" and axis != 0:
                expected[0] = 2 * expected[index] ** 2 / (30 * l0)
            if type_ == "BEAMC" and axis != 0:
                expected[0] = l0 * theta / (2 * math.sin(theta / 2)) - l0 + l0 * theta**2 / 40
            np.testing.assert_allclose(k.deformations(x), expected, rtol=0, atol=TOL * 4 * l0)
        # twist of both ends: only the relative twist counts
        psi_p, psi_q = rng.uniform(-1, 1, 2)
        x = configuration(np.zeros(3), [l0, 0, 0], axis_angle(C0[:, 0], psi_p), axis_angle(C0[:, 0], psi_q), p0, C0,
                          rigid)
        twist = psi_q - psi_p if type_ == "BEAMC" else math.sin(psi_q - psi_p)
        np.testing.assert_allclose(k.deformations(x), [0, l0 * twist, 0, 0, 0, 0], rtol=0, atol=TOL * 4 * l0)


def arc_configuration(l0, kappa):
    """Circular arc of length l0 and curvature κ bending about one local axis a ⟂ x (y or z):
    the chord runs along local x from the origin, of length l0 sin θ/θ, and the end sections
    are rotated by ∓θ = ∓κl0/2 about a relative to the chord (the arc's end tangents).
    Returns p, q (element frame) and the two end rotation angles."""
    th = kappa * l0 / 2
    chord_length = l0 * math.sin(th) / th
    return np.zeros(3), np.array([chord_length, 0, 0]), -th, th


@pytest.mark.parametrize("type_", BEAMS)
@pytest.mark.parametrize("axis", [1, 2], ids=["about_y", "about_z"])
def test_constant_curvature(type_, axis):
    """Constant curvature gives equal pair values e3 = e4 (e5 = e6) = −l0 sin(κl0/2) (as PLBEAM),
    the other pair and the torsion 0; BEAMNL: arc of length l0 ⇒ e1 = −(17/360) l0 θ⁴ + O(θ⁶);
    BEAMC: the angle, −l0 κl0/2, and no elongation."""
    rng = np.random.default_rng(31 + axis)
    pair = [2, 3] if axis == 1 else [4, 5]
    for _ in range(N_CONFIGS):
        k, l0, C0, p0 = straight_beam(type_, rng)
        kappa = rng.uniform(-2, 2)
        pl, ql, thp, thq = arc_configuration(l0, kappa)
        x = configuration(pl, ql, axis_angle(C0[:, axis], thp), axis_angle(C0[:, axis], thq), p0, C0,
                          random_rigid(rng))
        e = k.deformations(x)
        expected = -l0 * (kappa * l0 / 2 if type_ == "BEAMC" else math.sin(kappa * l0 / 2))
        np.testing.assert_allclose(e[pair], [expected, expected], rtol=0, atol=TOL * 4 * l0)
        if type_ == "BEAMC":
            assert abs(e[0]) < TOL * 8 * l0
        others = [i for i in range(1, 6) if i not in pair]
        np.testing.assert_allclose(e[others], 0.0, rtol=0, atol=TOL * 4 * l0)
    if type_ == "BEAMNL":
        k, l0, C0, p0 = straight_beam(type_, rng)
        for theta in (0.02, 0.01):
            pl, ql, thp, thq = arc_configuration(l0, 2 * theta / l0)
            x = configuration(pl, ql, axis_angle(C0[:, axis], thp), axis_angle(C0[:, axis], thq), p0, C0)
            ratio = k.deformations(x)[0] / (-17 / 360 * l0 * theta**4)
            assert abs(ratio - (1 - 109 / 714 * theta**2)) < 5e-6


def beam_stiffness(l0, EA, GIp, EIy, EIz):
    S = np.zeros((6, 6))
    S[0, 0] = EA / l0
    S[1, 1] = GIp / l0**3
    S[2:4, 2:4] = EIy / l0**3 * np.array([[4.0, -2.0], [-2.0, 4.0]])
    S[4:6, 4:6] = EIz / l0**3 * np.array([[4.0, -2.0], [-2.0, 4.0]])
    return S


@pytest.mark.parametrize("type_", BEAMS)
def test_beam_constitutive_matrix(type_):
    """ESTIFF EA GIp EIy EIz (§4.8); missing trailing values are 0."""
    rng = np.random.default_rng(37)
    for _ in range(5):
        l0 = rng.uniform(0.5, 2)
        values = list(rng.uniform(1, 1e4, 4))
        k = _testing.element_kernel(type_, l0=l0, lgeomy=[1, 0, 0, 0, 1, 0, 0, 0, 1])
        np.testing.assert_allclose(k.constitutive(values), beam_stiffness(l0, *values), rtol=1e-15, atol=0)
        for n in range(4):
            np.testing.assert_allclose(k.constitutive(values[:n]), beam_stiffness(l0, *(values[:n] + [0] * (4 - n))),
                                       rtol=1e-15, atol=0)


@pytest.mark.parametrize("type_", BEAMS)
@pytest.mark.parametrize("mode", ["bend_y", "bend_z", "twist"])
def test_beam_strain_energy(type_, mode):
    """½eᵀSe → ½EIy κ²l0 (about y), ½EIz κ²l0 (about z), ½GIp ψ²/l0 (pure twist ψ) for small κ, ψ.
    Bending: ratio = sin²θ/θ² + EA term = 1 − θ²/3 + (EA l0²/EI)θ²/144 + O(θ⁴), θ = κl0/2 (BEAMNL:
    the EA term is O(θ⁶)); twist: ratio = sin²ψ/ψ²."""
    rng = np.random.default_rng(41)
    for _ in range(5):
        k, l0, C0, p0 = straight_beam(type_, rng)
        EIy, EIz, GIp = rng.uniform(1, 10, 3)
        EA = max(EIy, EIz) * rng.uniform(10, 1000) / l0**2
        S = k.constitutive([EA, GIp, EIy, EIz])
        for small in (1e-2, 1e-3, 1e-4):
            if mode == "twist":
                x = configuration(np.zeros(3), [l0, 0, 0], IDENTITY, axis_angle(C0[:, 0], small), p0, C0,
                                  random_rigid(rng))
                exact, bound = 0.5 * GIp * small**2 / l0, small**2 / 3 * 1.01 + 1e-12
            else:
                axis = 1 if mode == "bend_y" else 2
                EI = EIy if axis == 1 else EIz
                pl, ql, thp, thq = arc_configuration(l0, small)
                x = configuration(pl, ql, axis_angle(C0[:, axis], thp), axis_angle(C0[:, axis], thq), p0, C0,
                                  random_rigid(rng))
                theta = small * l0 / 2
                exact = 0.5 * EI * small**2 * l0
                bound = (1 / 3 + EA * l0**2 / (144 * EI)) * theta**2 * 1.01 + 1e-9
            e = k.deformations(x)
            assert abs(0.5 * e @ S @ e / exact - 1) < bound


# ---------------------------------------------------------------------------------------------
# BEAM mass: rigid rod, Hermite model by quadrature, gravity
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("label", ["BEAM", "BEAM+rotary", "BEAMNL", "BEAMNL+rotary", "TRUSS"])
def test_rigid_rod_kinetic_energy(label):
    """A straight unstrained element moving rigidly (centre velocity u, global angular velocity
    ω, λ̇ = ½E(λ)ᵀω): T = ½m|u|² + ½ωᵀIω, I = (m l0²/12)(I − d dᵀ) (slender rod, d the axis),
    plus ½ l0 Ωᵀ diag(ρIp, ρIy, ρIz) Ω with Ω = C0ᵀR(λ)ᵀω (section frame) for rotary inertia;
    ½ẋᵀMẋ = T."""
    c = CASES[label]
    rng = np.random.default_rng(43)
    for _ in range(N_CONFIGS):
        ref = c.reference(c, rng)
        k = c.kernel(ref)
        l0, m = ref.l0, ref.emass[0] * ref.l0
        lam = random_unit_quaternion(rng)
        centre, u, omega = rng.uniform(-2, 2, 3), rng.normal(size=3), rng.normal(size=3)
        if c.type == "TRUSS":
            d = unit(rng.normal(size=3))
        else:
            C0 = np.reshape(ref.lgeomy, (3, 3)).T
            d = rotation_matrix(lam) @ C0[:, 0]
        rp, rq = -0.5 * l0 * d, 0.5 * l0 * d
        vp, vq = u + np.cross(omega, rp), u + np.cross(omega, rq)
        if c.type == "TRUSS":
            x, xd = np.concatenate([centre + rp, centre + rq]), np.concatenate([vp, vq])
        else:
            lamd = 0.5 * E_of(lam).T @ omega
            x = np.concatenate([centre + rp, lam, centre + rq, lam])
            xd = np.concatenate([vp, lamd, vq, lamd])
        np.testing.assert_allclose(k.deformations(x), 0.0, atol=1e-14 * l0)
        expected = 0.5 * m * u @ u + 0.5 * m * l0**2 / 12 * (omega @ omega - (omega @ d) ** 2)
        if len(ref.emass) > 1:
            Omega = C0.T @ rotation_matrix(lam).T @ omega
            expected += 0.5 * l0 * Omega @ (np.array(ref.emass[1:]) * Omega)
        np.testing.assert_allclose(k.kinetic_energy(x, xd), expected, rtol=1e-13)
        M, _ = k.mass(x, xd)
        np.testing.assert_allclose(0.5 * xd @ M @ xd, expected, rtol=1e-13)


def test_rotary_inertia_adds_section_energy():
    """EMASS ρA ρIp ρIy ρIz: the kernel's T minus the T of EMASS ρA alone equals
    (l0/6)(Ω_pᵀJΩ_p + Ω_pᵀJΩ_q + Ω_qᵀJΩ_q), Ω = C0ᵀ 2G(λ)λ̇, J = diag(ρIp, ρIy, ρIz) (§4.8), at
    arbitrary (deformed, non-unit λ) states; ρIy, ρIz default to 0."""
    c = CASES["BEAM+rotary"]
    for rng, ref, k, x in samples_on_and_off_sphere(c, "rotary"):
        xd = rng.normal(size=14)
        C0 = np.reshape(ref.lgeomy, (3, 3)).T
        for emass in (ref.emass, ref.emass[:2], ref.emass[:3]):
            J = np.diag(list(emass[1:]) + [0.0] * (4 - len(emass)))
            Op = C0.T @ (2 * G_of(x[3:7]) @ xd[3:7])
            Oq = C0.T @ (2 * G_of(x[10:14]) @ xd[10:14])
            T_rot = ref.l0 / 6 * (Op @ J @ Op + Op @ J @ Oq + Oq @ J @ Oq)
            full = _testing.element_kernel("BEAM", l0=ref.l0, lgeomy=list(ref.lgeomy), emass=list(emass))
            plain = _testing.element_kernel("BEAM", l0=ref.l0, lgeomy=list(ref.lgeomy), emass=[emass[0]])
            np.testing.assert_allclose(full.kinetic_energy(x, xd) - plain.kinetic_energy(x, xd), T_rot,
                                       rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("label", ["BEAM", "BEAM+rotary", "BEAMNL+rotary"])
def test_beam_mass_model_by_quadrature(label):
    """§4.8 by Gauss quadrature, independent of the coded mass points: r(ξ) = H1x_p + H2 l0 R(λp)e_x0
    + H3x_q + H4 l0 R(λq)e_x0, N = [H1 I, H2 l0 T(λp), H3 I, H4 l0 T(λq)], M = ρA l0 ∫NᵀN,
    h = ρA l0 ∫Nᵀa_r with a_r = 2 l0 [H2 R(λ̇p) + H4 R(λ̇q)] e_x0, V = −ρA l0 ∫ g·r; rotary inertia
    (exact Lagrange form of T_rot): M += 4G_iᵀA_ijG_j, h_i += 4G(λ̇_i)ᵀΣ_j A_ij ω_j,
    A = (l0/6)[[2, 1], [1, 2]] ⊗ C0 J C0ᵀ, ω_j = 2G(λ_j)λ̇_j. Unit and non-unit λ."""
    c = CASES[label]
    for rng, ref, k, x in samples_on_and_off_sphere(c, "hermite"):
        xd, g = rng.normal(size=14), rng.normal(size=3) * 10
        rhoA, l0 = ref.emass[0], ref.l0
        C0 = np.reshape(ref.lgeomy, (3, 3)).T
        ex0 = C0[:, 0]
        lp, lq, lpd, lqd = x[3:7], x[10:14], xd[3:7], xd[10:14]
        M = np.zeros((14, 14))
        h = np.zeros(14)
        V = 0.0
        for xi, w in zip(GAUSS_XI, GAUSS_W):
            H = hermite(xi)
            r = H[0] * x[0:3] + H[1] * l0 * rotation_matrix(lp) @ ex0 + H[2] * x[7:10] + H[3] * l0 * rotation_matrix(lq) @ ex0
            N = np.zeros((3, 14))
            N[:, 0:3] = H[0] * np.eye(3)
            N[:, 3:7] = H[1] * l0 * T_of(lp, ex0)
            N[:, 7:10] = H[2] * np.eye(3)
            N[:, 10:14] = H[3] * l0 * T_of(lq, ex0)
            a_r = 2 * l0 * (H[1] * rotation_matrix(lpd) + H[3] * rotation_matrix(lqd)) @ ex0
            M += rhoA * l0 * w * N.T @ N
            h += rhoA * l0 * w * N.T @ a_r
            V -= rhoA * l0 * w * g @ r
        if len(ref.emass) > 1:
            A = C0 @ np.diag(ref.emass[1:]) @ C0.T
            blocks = [slice(3, 7), slice(10, 14)]
            Gs = [G_of(x[b]) for b in blocks]
            om = [2 * Gs[i] @ xd[b] for i, b in enumerate(blocks)]
            for i, bi in enumerate(blocks):
                for j, bj in enumerate(blocks):
                    Aij = l0 / 6 * (2 if i == j else 1) * A
                    M[bi, bj] += 4 * Gs[i].T @ Aij @ Gs[j]
                    h[bi] += 4 * G_of(xd[bi]).T @ Aij @ om[j]
        Mk, hk = k.mass(x, xd)
        assert rel_err(Mk, M) < 1e-13
        assert rel_err(hk, h) < 1e-13
        np.testing.assert_allclose(k.kinetic_energy(x, xd), 0.5 * xd @ M @ xd, rtol=1e-13)
        np.testing.assert_allclose(k.gravity_potential(x, g), V, rtol=1e-12, atol=1e-12 * abs(V) + 1e-13)


@pytest.mark.parametrize("label", ["TRUSS", "BEAM", "BEAMNL+rotary"])
def test_gravity_loads(label):
    """½ρAl0 g on each position node (total m g); BEAM: (ρAl0²/12) T_{e_x0}(λp)ᵀg on λp and
    −(ρAl0²/12) T_{e_x0}(λq)ᵀg on λq (§4.1, §4.8); rotary inertia gets no gravity."""
    c = CASES[label]
    for rng, ref, k, x in samples_on_and_off_sphere(c, "gravity-closed"):
        g = rng.normal(size=3) * 10
        rhoA, l0 = ref.emass[0], ref.l0
        f = k.gravity(x, g)
        if c.type == "TRUSS":
            expected = np.concatenate([0.5 * rhoA * l0 * g, 0.5 * rhoA * l0 * g])
        else:
            ex0 = np.reshape(ref.lgeomy, (3, 3)).T[:, 0]
            mom = rhoA * l0**2 / 12
            expected = np.concatenate([0.5 * rhoA * l0 * g, mom * T_of(x[3:7], ex0).T @ g,
                                       0.5 * rhoA * l0 * g, -mom * T_of(x[10:14], ex0).T @ g])
        assert rel_err(f, expected) < 1e-14


# ---------------------------------------------------------------------------------------------
# TRUSS: closed forms of §4.1 (as PLTRUSS in 3-D)
# ---------------------------------------------------------------------------------------------

def test_truss_closed_forms():
    """e1 = l − l0, B = [−e_lᵀ, e_lᵀ], H = (1/l)[[P, −P], [−P, P]], c1 = (v·v − (e_l·v)²)/l,
    M = (ρAl0/6)[[2I, I], [I, 2I]], h = 0, S = EA/l0 (§4.1)."""
    for rng, ref, k, x in CASES["TRUSS"].samples("closed-forms"):
        d = x[3:6] - x[0:3]
        l = np.linalg.norm(d)
        el = d / l
        P = np.eye(3) - np.outer(el, el)
        xd = rng.normal(size=6)
        v = xd[3:] - xd[:3]
        sigma = rng.normal()
        np.testing.assert_allclose(k.first_derivatives(x), [np.concatenate([-el, el])], rtol=0, atol=1e-15)
        np.testing.assert_allclose(k.stress_hessian(x, [sigma]), sigma / l * np.block([[P, -P], [-P, P]]),
                                   rtol=0, atol=1e-14 * abs(sigma) / l)
        np.testing.assert_allclose(k.convective(x, xd), [(v @ v - (el @ v) ** 2) / l], rtol=1e-12)
        M, h = k.mass(x, xd)
        I3 = np.eye(3)
        np.testing.assert_allclose(M, ref.emass[0] * ref.l0 / 6 * np.block([[2 * I3, I3], [I3, 2 * I3]]), rtol=1e-14)
        assert not h.any()
        EA = rng.uniform(1, 1e4)
        np.testing.assert_allclose(k.constitutive([EA]), [[EA / ref.l0]], rtol=1e-15)


def test_truss_in_plane_equals_pltruss():
    """A TRUSS in the x–y plane has the deformation, B, c, T, M and gravity of the PLTRUSS."""
    rng = np.random.default_rng(47)
    for _ in range(N_CONFIGS):
        l0, rhoA = rng.uniform(0.5, 2), rng.uniform(0.5, 3)
        k3 = _testing.element_kernel("TRUSS", l0=l0, emass=[rhoA])
        k2 = _testing.element_kernel("PLTRUSS", l0=l0, emass=[rhoA])
        x2, v2, g = rng.uniform(-2, 2, 4), rng.normal(size=4), rng.normal(size=3)
        x2[2:] = x2[:2] + l0 * (unit(rng.normal(size=2)) + rng.uniform(-0.2, 0.2, 2))
        J = np.zeros((6, 4))
        J[[0, 1, 3, 4], [0, 1, 2, 3]] = 1.0
        x3, v3 = J @ x2, J @ v2
        np.testing.assert_allclose(k3.deformations(x3), k2.deformations(x2), rtol=0, atol=1e-15 * l0)
        np.testing.assert_allclose(k3.first_derivatives(x3) @ J, k2.first_derivatives(x2), rtol=0, atol=1e-15)
        np.testing.assert_allclose(k3.convective(x3, v3), k2.convective(x2, v2), rtol=1e-13)
        np.testing.assert_allclose(k3.kinetic_energy(x3, v3), k2.kinetic_energy(x2, v2), rtol=1e-14)
        np.testing.assert_allclose(J.T @ k3.mass(x3, v3)[0] @ J, k2.mass(x2, v2)[0], rtol=1e-14)
        np.testing.assert_allclose(J.T @ k3.gravity(x3, g), k2.gravity(x2, g), rtol=1e-14)


# ---------------------------------------------------------------------------------------------
# HINGE
# ---------------------------------------------------------------------------------------------

def hinge_relative(lam1, C0, phi, theta_y=0.0, theta_z=0.0):
    """λ2 = λ1 ⊗ rot(e_x0, φ) ⊗ rot(e_y0, θy) ⊗ rot(e_z0, θz): o2 turned about the hinge axis by φ
    relative to o1, then tilted about its own local y, z; R̂ = Rx(φ)Ry(θy)Rz(θz)."""
    lam2 = quat_mul(lam1, axis_angle(C0[:, 0], phi))
    lam2 = quat_mul(lam2, axis_angle(C0[:, 1], theta_y))
    return quat_mul(lam2, axis_angle(C0[:, 2], theta_z))


ALL_AXES = SPECIAL_AXES + [tuple(np.random.default_rng(53 + i).normal(size=3)) for i in range(8)]


@pytest.mark.parametrize("axis", ALL_AXES, ids=lambda a: "({:.3g},{:.3g},{:.3g})".format(*a))
def test_hinge_rotation_angle_frame_rule_and_misalignment_signs(axis):
    """For o2 = o1 turned by φ about the axis and tilted by θ about its local y (z):
    R̂ = Rx(φ)Ry(θ) ⇒ e = (φ, sin θ, 0); R̂ = Rx(φ)Rz(θ) ⇒ e = (φ, 0, sin θ) — exactly, with
    e1 = φ on (−π, π] (no wrapping in the interior) and the hinge frame of §4.10 (a different
    e_y0 would mix e2 and e3). Small θ: e2 = R̂13 ≈ θ about local y, e3 = −R̂12 ≈ θ about local z."""
    k = _testing.element_kernel("HINGE", params=list(axis))
    C0 = hinge_frame(axis)
    rng = np.random.default_rng(59)
    phis = list(np.linspace(-math.pi, math.pi, 25)[1:-1]) + [math.pi - 1e-9, -math.pi + 1e-9, 0.0, math.pi]
    for phi in phis:
        lam1 = random_unit_quaternion(rng)
        for theta in (rng.uniform(-1.2, 1.2), 1e-4):
            for tilt, expected in (((theta, 0.0), [phi, math.sin(theta), 0.0]),
                                   ((0.0, theta), [phi, 0.0, math.sin(theta)])):
                e = k.deformations(np.concatenate([lam1, hinge_relative(lam1, C0, phi, *tilt)]))
                np.testing.assert_allclose(e[1:], expected[1:], rtol=0, atol=1e-14)
                if phi != math.pi:
                    assert abs(e[0] - phi) < 1e-14
                else:  # a half turn: ±π within the round-off of composing λ2 (either branch)
                    assert abs(wrap_to_pi(e[0] - phi)) < 1e-14
    # the branch at an exactly representable half turn is +π: (−π, π]
    for i in range(3):
        x = np.concatenate([IDENTITY, axis_angle(np.eye(3)[i], math.pi)])
        assert _testing.element_kernel("HINGE", params=list(np.eye(3)[i])).deformations(x)[0] == math.pi
    np.testing.assert_allclose(k.constitutive([3.5]), np.diag([3.5, 0.0, 0.0]), rtol=0, atol=0)
    assert not k.constitutive([]).any()


def test_hinge_frame_rule_examples():
    """The frames of §4.10 for a few axes, written out (ties → first global axis)."""
    s2 = math.sqrt(0.5)
    np.testing.assert_allclose(hinge_frame((0, 0, 1))[:, 1], [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(hinge_frame((1, 0, 0))[:, 1], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(hinge_frame((1, 1, 0))[:, 1], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(hinge_frame((0, 1, 1))[:, 1], [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(hinge_frame((1, 0, 1))[:, 1], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(hinge_frame((2, 1, -1))[:, 1], unit(np.array([0, 1, 0]) - 1 / 6 * np.array([2, 1, -1])),
                               atol=1e-15)
    np.testing.assert_allclose(hinge_frame((1, 1, 1))[:, 1], unit([2, -1, -1]), atol=1e-15)
    np.testing.assert_allclose(hinge_frame((0, 1, -1)), [[0, 1, 0], [s2, 0, -s2], [-s2, 0, -s2]], atol=1e-15)


def test_hinge_rotation_is_right_handed_about_the_given_axis():
    """e1 > 0 for a right-hand rotation of o2 about +axis; the opposite axis flips the sign."""
    for axis in ((0, 0, 1), (1, 2, 3)):
        lam2 = axis_angle(axis, 0.4)
        x = np.concatenate([IDENTITY, lam2])
        assert abs(_testing.element_kernel("HINGE", params=list(axis)).deformations(x)[0] - 0.4) < 1e-15
        assert abs(_testing.element_kernel("HINGE", params=[-a for a in axis]).deformations(x)[0] + 0.4) < 1e-15


def relative_rotation_jacobian(k, x):
    """∂e/∂θ for a global rotation increment δθ of o2 alone (δλ2 = ½E(λ2)ᵀδθ) and of both nodes
    together (a rigid rotation: must give 0)."""
    B = k.first_derivatives(x)
    J2 = B[:, 4:8] @ (0.5 * E_of(x[4:8]).T)
    Jboth = B[:, 0:4] @ (0.5 * E_of(x[0:4]).T) + J2
    return J2, Jboth


@pytest.mark.parametrize("axis", ALL_AXES[:12], ids=lambda a: "({:.3g},{:.3g},{:.3g})".format(*a))
def test_hinge_regular_at_half_turn(axis):
    """At e1 = ±π (rotations of ±179.9° and ±180°, with and without misalignment) B restricted
    to the relative rotation has rank 3: without misalignment the 3×3 map from the rotation
    increment of o2 to (e1, e2, e3) is orthogonal (singular values 1), with a misalignment
    ≤ 0.1 rad all singular values stay ≥ 0.8. A common rotation of both nodes changes nothing.
    Contrast: the antisymmetric misalignments (R̂13 − R̂31)/2, (R̂21 − R̂12)/2 lose rank there."""
    k = _testing.element_kernel("HINGE", params=list(axis))
    C0 = hinge_frame(axis)
    rng = np.random.default_rng(61)
    for deg in (179.9, 180.0, -179.9, -180.0):
        phi = math.radians(deg)
        for tilt in ((0.0, 0.0), tuple(rng.uniform(-0.1, 0.1, 2))):
            lam1 = random_unit_quaternion(rng)
            x = np.concatenate([lam1, hinge_relative(lam1, C0, phi, *tilt)])
            e1 = k.deformations(x)[0]
            assert abs(wrap_to_pi(e1 - phi)) < (1e-14 if tilt == (0.0, 0.0) else 0.02)
            J2, Jboth = relative_rotation_jacobian(k, x)
            sv = np.linalg.svd(J2, compute_uv=False)
            if tilt == (0.0, 0.0):
                np.testing.assert_allclose(sv, 1.0, rtol=0, atol=1e-13)
            else:
                assert sv.min() > 0.8
            np.testing.assert_allclose(Jboth, 0.0, rtol=0, atol=1e-14)

            def antisymmetric(l2, lam1=lam1):
                Rh = C0.T @ rotation_matrix(lam1).T @ rotation_matrix(l2) @ C0
                return np.array([(Rh[0, 2] - Rh[2, 0]) / 2, (Rh[1, 0] - Rh[0, 1]) / 2])
            Ja = jacobian_fd(antisymmetric, x[4:8], np.full(4, 1e-3)) @ (0.5 * E_of(x[4:8]).T)
            if tilt == (0.0, 0.0):
                assert np.linalg.svd(Ja, compute_uv=False)[0] < 1e-3  # both rows (nearly) vanish


# ---------------------------------------------------------------------------------------------
# L2MIN1
# ---------------------------------------------------------------------------------------------

def test_l2min1_exact():
    """e = λᵀλ − 1, B = 2λᵀ, c = 2λ̇ᵀλ̇, Σσ H = 2σ I (§4.13), exactly (unit and non-unit λ)."""
    c = CASES["L2MIN1"]
    for rng, _, k, lam in samples_on_and_off_sphere(c, "exact"):
        lamd, sigma = rng.normal(size=4), rng.normal()
        # Round-off of λᵀλ near 1 (NumPy's summation order depends on the memory alignment): ulps of 1.
        np.testing.assert_allclose(k.deformations(lam), [lam @ lam - 1.0], rtol=0, atol=4 * np.finfo(float).eps)
        np.testing.assert_array_equal(k.first_derivatives(lam), [2.0 * lam])
        np.testing.assert_allclose(k.convective(lam, lamd), [2.0 * lamd @ lamd], rtol=1e-15, atol=0)
        np.testing.assert_array_equal(k.stress_hessian(lam, [sigma]), 2.0 * sigma * np.eye(4))
        assert not k.constitutive([1.0]).any()


# ---------------------------------------------------------------------------------------------
# Kernel construction errors
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("type_, kwargs", [("BEAM", {}), ("BEAMNL", {"lgeomy": [1, 0, 0]}), ("HINGE", {}),
                                           ("HINGE", {"params": [0, 1]}), ("HINGE", {"params": [0, 0, 0]})],
                         ids=["BEAM-no-lgeomy", "BEAMNL-short-lgeomy", "HINGE-no-axis", "HINGE-short-axis",
                              "HINGE-zero-axis"])
def test_kernel_rejects_missing_geometry(type_, kwargs):
    """Missing or incomplete LGEOMY / axis: an InputError, not an out-of-range read."""
    with pytest.raises(_core.InputError):
        _testing.element_kernel(type_, **kwargs)
