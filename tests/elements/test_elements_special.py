"""Element-level verification of the special elements PLBEAR, BEARING, SURFACE, PLWHEEL, WHEEL
and PLBELT (issue #6; formulation.md §4.5–4.7, §4.11, §4.12, §4.14, §10.1) through
`spacar._testing.element_kernel`.

Generic checks (support/element_checks.py, at N_CONFIGS random configurations, unit and non-unit Euler
parameters): B, the convective term c, Σσ_iΓ_i, mass and gravity against differences. Wheel slips
are velocity-level deformations (only ė = B(x)ẋ exists), so for those rows

* B is compared with differences in v of the kernel's own rate function ė(x, v) (linear in v),
* c = ∂(B(x)v)/∂x · v with differences of x ↦ B(x)v along v,
* Γ_i = ∂(B_iᵀ)/∂x (the generic Σσ_iΓ_i check already differences Bᵀσ, all rows).

Rigid-motion invariance holds for PLBEAR, BEARING and PLBELT (modulo the period of their
angle-type deformations: 2π for the BEARING rotation, 2π|r2 − r1| for the belt). SURFACE, PLWHEEL
and WHEEL are ground-referenced; they are checked against closed forms and independent
computations instead: the quadric, the 3-D rigid-body velocity of the wheel's contact point
(v_c = ẋ_p + ω × (x_c − x_p) with ω from differences of R(λ(t)) and x_c found by minimising
over the rim), and the WHEEL contact height e1 = n·x − r s.

PLBELT (§10.1): the belt length computed independently (tangent points found by a Newton
solve of the tangency conditions, wound arcs from the material end points carried by the
pulleys) minus its reference equals e1; ė1 = s·(ċ2 − ċ1) + r1β̇1 − r2β̇2, also along a
simulated motion with e1 rigid and a moving pulley centre; the kinetic energy and gravity
potential against Gauss quadrature of the belt material (arcs rigid with the pulleys, span
velocity linear between the tangent points); the mass matrix against Lagrange (generic).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.optimize
import pytest

import spacar
from support.element_checks import (  # noqa: F401  (record: fixture used by the generic checks)
    N_CONFIGS,
    REL_TOL,
    STEP_FIRST,
    STEP_SECOND,
    ElementCase,
    GenericElementChecks,
    Reference,
    assemble,
    coordinate_scales,
    directional_derivative_fd,
    jacobian_fd,
    quat_mul,
    random_configuration,
    random_rigid_motion,
    random_unit_quaternion,
    record,
    rel_err,
    rotation_matrix,
    second_directional_fd,
    skew,
)
from support.spatial_models import E_ as E_of, hinge_frame, unit
from spacar import _core, _testing

TOL = 1e-13  # closed forms: round-off of a few operations on O(1) numbers


def rot2(b):
    return np.array([[math.cos(b), -math.sin(b)], [math.sin(b), math.cos(b)]])


def velocity_rows(k):
    return [i for i in range(k.n_deformations) if k.velocity_level(i)]


# ---------------------------------------------------------------------------------------------
# Reference geometries
# ---------------------------------------------------------------------------------------------

def plbear_ref(case, rng):
    """Two planar frames at a random distance l0 ∈ [0.5, 2]; d0 = x_p2 − x_p1 (LGEOMY)."""
    l0 = rng.uniform(0.5, 2.0)
    p = rng.uniform(-2, 2, 2)
    q = p + l0 * unit(rng.normal(size=2))
    return Reference(x=assemble(case.kinds, [p, q]), lgeomy=tuple(q - p), scale=l0)


SPECIAL_AXES = [(0, 0, 1), (1, 0, 0), (0, 1, 0), (1, 1, 1), (0.3, -0.3, 2), (0, -1, 1)]


def bearing_ref(case, rng):
    """Two spatial frames; a special or random axis; d0 = C0ᵀ(x_p2 − x_p1) (LGEOMY)."""
    i = rng.integers(0, 2 * len(SPECIAL_AXES))
    axis = np.array(SPECIAL_AXES[i], float) if i < len(SPECIAL_AXES) else rng.normal(size=3)
    l0 = rng.uniform(0.5, 2.0)
    p = rng.uniform(-2, 2, 3)
    q = p + l0 * unit(rng.normal(size=3))
    return Reference(x=assemble(case.kinds, [p, q]), params=tuple(axis),
                     lgeomy=tuple(hinge_frame(axis).T @ (q - p)), scale=l0)


def surface_ref(case, rng):
    """A random quadric (coefficients c1..c10 of §4.12) and a random point."""
    return Reference(x=rng.uniform(-1.5, 1.5, 3), params=tuple(rng.normal(size=10)))


def plwheel_ref(case, rng):
    """Radius r ∈ [0.2, 1], a random axle direction (unnormalised)."""
    r = rng.uniform(0.2, 1.0)
    axis = rng.normal(size=2) * rng.uniform(0.3, 3)
    return Reference(x=assemble(case.kinds, [rng.uniform(-2, 2, 2)]), params=(r, *axis), scale=r)


def wheel_ref(normal):
    """Radius r ∈ [0.2, 1], a random axle; ground normal default (None), given or random."""
    def reference(case, rng):
        r = rng.uniform(0.2, 1.0)
        axis = rng.normal(size=3) * rng.uniform(0.3, 3)
        n = rng.normal(size=3) * rng.uniform(0.3, 3) if normal == "random" else normal
        params = (*axis, r) if n is None else (*axis, r, *n)
        return Reference(x=assemble(case.kinds, [rng.uniform(-2, 2, 3)]), params=params, scale=r)
    return reference


def quadric_params(Q, b, c):
    """SURFACE/WHEEL coefficients c1..c10 of f(x) = xᵀQx + bᵀx + c."""
    return (Q[0, 0], Q[1, 1], Q[2, 2], 2 * Q[0, 1], 2 * Q[1, 2], 2 * Q[0, 2], *b, c)


def quadric_of(params):
    c = params
    Q = np.array([[c[0], c[3] / 2, c[5] / 2], [c[3] / 2, c[1], c[4] / 2], [c[5] / 2, c[4] / 2, c[2]]])
    return Q, np.array(c[6:9]), c[9]


def wheel_quadric_ref(kind):
    """A WHEEL on a quadratic surface (params ax ay az r c1..c10), its centre about r from the
    surface on the positive side: outside a ball ("ball"), inside a spherical bowl ("bowl"), or
    outside a randomly rotated and shifted ellipsoid with semi-axes 2.5..4 ("ellipsoid"), r ≤ 0.6
    so that the surface is curved less than the rim."""
    def reference(case, rng):
        r = rng.uniform(0.2, 0.6)
        axis = rng.normal(size=3) * rng.uniform(0.3, 3)
        c0 = rng.uniform(-1, 1, 3)
        d = unit(rng.normal(size=3))
        if kind == "ellipsoid":
            Rq = rotation_matrix(unit(rng.normal(size=4)))
            Q = Rq @ np.diag(1 / rng.uniform(2.5, 4.0, 3) ** 2) @ Rq.T
            p = c0 + d * (1 / math.sqrt(d @ Q @ d) + r * rng.uniform(0.5, 1.5))
            sign = 1.0
        else:
            Rs = rng.uniform(2.0, 4.0)
            Q = np.eye(3) / Rs ** 2
            sign = 1.0 if kind == "ball" else -1.0
            p = c0 + d * (Rs + sign * r * rng.uniform(0.5, 1.5))
        # f = sign ((x − c0)ᵀQ(x − c0) − 1), positive on the wheel's side
        params = quadric_params(sign * Q, sign * (-2 * Q @ c0), sign * (c0 @ Q @ c0 - 1))
        return Reference(x=assemble(case.kinds, [p]), params=(*axis, r, *params), scale=r)
    return reference


def wheel_normal(params, p):
    """The unit normal the contact is taken against: the plane's, or ∇f at the centre."""
    if len(params) == 14:
        Q, b, _ = quadric_of(params[4:])
        return unit(2 * Q @ p + b)
    return unit(params[4:7]) if len(params) == 7 else np.array([0.0, 0.0, 1.0])


def plbelt_ref(equal_radii=False):
    """Pulley centres L0 ∈ [0.5, 2] apart (LENGTHO, LGEOMY α0), radii r_i ∈ [0.05, 0.3] L0, ρA and
    wound angles a1⁰, a2⁰ ∈ [4, 6] rad (so that the arcs stay positive for β ∈ [−π, π])."""
    def reference(case, rng):
        L0 = rng.uniform(0.5, 2.0)
        alpha0 = rng.uniform(-math.pi, math.pi)
        c1 = rng.uniform(-2, 2, 2)
        c2 = c1 + L0 * np.array([math.cos(alpha0), math.sin(alpha0)])
        r1 = rng.uniform(0.05, 0.3) * L0
        r2 = r1 if equal_radii else rng.uniform(0.05, 0.3) * L0
        emass = (rng.uniform(0.5, 3.0), rng.uniform(4, 6), rng.uniform(4, 6))
        return Reference(x=assemble(case.kinds, [c1, c2]), l0=L0, lgeomy=(alpha0,), params=(r1, r2),
                         emass=emass, scale=L0)
    return reference


class WheelCase(ElementCase):
    """WHEEL configurations away from the flat-lying disc (s = |a × n| ≥ 0.3; at s = 0 the
    contact point is undefined). Off the unit sphere the axle a = R(λ)â0 has length |λ|², and
    s = √(1 − (n·a)²) exists only while |n·a| < 1: the norms are drawn from [0.9, 1.1] there.
    The slips contain 1/s: their higher derivatives are large, and the second differences of the
    convective check take a smaller step (truncation error ~1e-6 relative at the generic step,
    ~1e-10 at this one)."""

    second_step = 3e-3

    def samples(self, check, n=N_CONFIGS, off_sphere=False):
        rng = self.rng(check + ("@off-sphere" if off_sphere else ""))
        count = 0
        while count < n:
            ref = self.reference(self, rng)
            x = random_configuration(rng, self.kinds, ref, lambda_norms=(0.9, 1.1) if off_sphere else None)
            a = rotation_matrix(x[3:7]) @ unit(ref.params[0:3])
            nrm = wheel_normal(ref.params, x[0:3])
            if 1.0 - (nrm @ a) ** 2 < 0.09:
                continue
            count += 1
            yield rng, ref, self.kernel(ref), x


INVARIANT_CASES = [
    ElementCase("PLBEAR", plbear_ref),
    ElementCase("BEARING", bearing_ref, angles=(3,)),
    ElementCase("PLBELT", plbelt_ref()),
    ElementCase("PLBELT", plbelt_ref(equal_radii=True), label="PLBELT-r1=r2"),
]
GROUND_CASES = [
    ElementCase("SURFACE", surface_ref),
    ElementCase("PLWHEEL", plwheel_ref),
    WheelCase("WHEEL", wheel_ref(None)),
    WheelCase("WHEEL", wheel_ref((0.0, 0.0, -1.0)), label="WHEEL-n=-z"),
    WheelCase("WHEEL", wheel_ref("random"), label="WHEEL-n=random"),
    WheelCase("WHEEL", wheel_quadric_ref("ball"), label="WHEEL-ball"),
    WheelCase("WHEEL", wheel_quadric_ref("bowl"), label="WHEEL-bowl"),
    WheelCase("WHEEL", wheel_quadric_ref("ellipsoid"), label="WHEEL-ellipsoid"),
]
CASES = {str(c): c for c in INVARIANT_CASES + GROUND_CASES}


# ---------------------------------------------------------------------------------------------
# Generic checks, with velocity-level rows
# ---------------------------------------------------------------------------------------------

def first_derivative_error(k, x, scales):
    """B against differences: holonomic rows of e(x), velocity-level rows of ė(x, v) in v."""
    B = k.first_derivatives(x)
    B_fd = jacobian_fd(k.deformations, x, STEP_FIRST * scales)
    vel = velocity_rows(k)
    if vel:
        B_fd[vel] = jacobian_fd(lambda v: k.rates(x, v), np.zeros(x.size), scales)[vel]
    return rel_err(B, B_fd)


def convective_error(k, x, v, step=STEP_SECOND):
    """c against second differences of e along v (holonomic rows) and against differences of
    x ↦ B(x)v along v (velocity-level rows)."""
    c = k.convective(x, v)
    h = step / np.max(np.abs(v))
    c_fd = second_directional_fd(k.deformations, x, v, h)
    vel = velocity_rows(k)
    if vel:
        c_fd[vel] = directional_derivative_fd(lambda y: k.first_derivatives(y) @ v, x, v, h)[vel]
    return rel_err(c, c_fd)


class VelocityRowChecks(GenericElementChecks):
    """The generic B and c checks, extended to velocity-level rows; and the rates ė(x, v) of the
    kernel equal B(x)v (holonomic rows: the directional derivative of e)."""

    first_derivative_error = staticmethod(first_derivative_error)

    @staticmethod
    def convective_error(case, k, x, v):
        return convective_error(k, x, v, getattr(case, "second_step", STEP_SECOND))

    def test_stress_hessian_matches_differences(self, case, record):
        """Σσ_iΓ_i against differences of Bᵀσ. Γ_i = H_i is symmetric for holonomic rows only:
        B_i of a velocity-level row is no gradient, and its Γ_i = ∂(B_iᵀ)/∂x is not symmetric."""
        worst_all = 0.0
        for suffix, samples in case.derivative_samples("G"):
            worst = 0.0
            for rng, ref, k, x in samples:
                sigma = rng.normal(size=k.n_deformations)
                holonomic = sigma.copy()
                holonomic[velocity_rows(k)] = 0.0
                Gh = k.stress_hessian(x, holonomic)
                assert rel_err(Gh, Gh.T) < 1e-13
                scales = coordinate_scales(case.kinds, ref)
                G = k.stress_hessian(x, sigma)
                G_fd = jacobian_fd(lambda y: k.first_derivatives(y).T @ sigma, x, STEP_FIRST * scales)
                worst = max(worst, rel_err(G, G_fd))
            record(case, "G" + suffix, worst)
            worst_all = max(worst_all, worst)
        assert worst_all < REL_TOL

    def test_rates_equal_B_times_v(self, case, record):
        worst = 0.0
        for rng, ref, k, x in case.samples("rates"):
            v = rng.normal(size=x.size) * coordinate_scales(case.kinds, ref)
            worst = max(worst, rel_err(k.first_derivatives(x) @ v, k.rates(x, v)))
        record(case, "rates", worst)
        assert worst < 1e-14


class TestInvariantSpecialElements(VelocityRowChecks):
    """PLBEAR, BEARING, PLBELT: generic checks; e invariant under rigid motion modulo the period
    of each deformation; e = 0 at the reference."""

    @pytest.fixture(params=INVARIANT_CASES, ids=str)
    def case(self, request):
        return request.param

    def test_deformations_invariant_under_rigid_motion(self, case, record):
        worst = 0.0
        for rng, ref, k, x in case.samples("rigid"):
            move = random_rigid_motion(rng, case.kinds, ref.scale)
            d = k.deformations(move(x)) - k.deformations(x)
            for i in range(k.n_deformations):
                p = k.period(i)
                if p > 0:
                    d[i] -= p * round(d[i] / p)
            worst = max(worst, float(np.max(np.abs(d))))
        record(case, "rigid", worst)
        assert worst < 1e-12


class TestGroundReferencedElements(VelocityRowChecks):
    """SURFACE, PLWHEEL, WHEEL: generic derivative checks (velocity-level rows included); not
    invariant under rigid motion (ground-referenced, §1.2) — see the closed forms below."""

    @pytest.fixture(params=GROUND_CASES, ids=str)
    def case(self, request):
        return request.param

    test_deformations_invariant_under_rigid_motion = None
    test_deformations_vanish_at_reference = None


def test_velocity_level_flags():
    """Only the wheel slips are velocity-level: PLWHEEL e1, e2; WHEEL e2, e3 — in the kernels and
    in the element catalogue (which the dump writer uses), for every element type."""
    expected = {"PLWHEEL": [0, 1], "WHEEL": [1, 2]}
    for label, c in CASES.items():
        for _, _, k, _ in c.samples("flags", n=1):
            assert velocity_rows(k) == expected.get(c.type, []), label
    for t in _core.element_catalogue():
        assert [i for i, v in enumerate(t.velocity_level) if v] == expected.get(t.name, []), t.name
        assert len(t.velocity_level) == t.n_deformations


def test_ground_referenced_elements_are_not_invariant():
    """The closed-form checks replace invariance for these: a rigid motion does change e or ė."""
    rng = np.random.default_rng(5)
    for label in ("SURFACE", "PLWHEEL", "WHEEL"):
        c = CASES[label]
        for _, ref, k, x in c.samples("not-invariant", n=3):
            move = random_rigid_motion(rng, c.kinds, ref.scale)
            v = rng.normal(size=x.size)
            before = np.concatenate([k.deformations(x), k.rates(x, v)])
            after = np.concatenate([k.deformations(move(x)), k.rates(move(x), v)])
            assert np.max(np.abs(after - before)) > 1e-3, label


# ---------------------------------------------------------------------------------------------
# PLBEAR and BEARING: closed forms
# ---------------------------------------------------------------------------------------------

def test_plbear_closed_form_and_stiffness():
    """[e1; e2] = R(β_o1)ᵀ(x_p2 − x_p1) − d0, e3 = β_o2 − β_o1 (§4.5); σ = diag(Sx, Sy, St) e for
    ESTIFF and, in the same form, EDAMPP."""
    c = CASES["PLBEAR"]
    for rng, ref, k, x in c.samples("closed"):
        d0 = np.array(ref.lgeomy)
        expected = np.concatenate([rot2(x[2]).T @ (x[3:5] - x[0:2]) - d0, [x[5] - x[2]]])
        np.testing.assert_allclose(k.deformations(x), expected, atol=TOL)
        s = rng.uniform(1, 100, 3)
        np.testing.assert_allclose(k.constitutive(list(s)), np.diag(s), rtol=0, atol=0)
    assert not k.has_mass


def test_plbear_revolute_joint_use():
    """Rigid e1, e2 with e3 free: p2 coincides with p1 + R(β_o1)d0 whatever the rotations."""
    k = _testing.element_kernel("PLBEAR", lgeomy=[0.0, 0.0])
    x = np.array([0.3, -0.2, 1.1, 0.3, -0.2, -2.0])
    np.testing.assert_allclose(k.deformations(x), [0, 0, -3.1], atol=TOL)


def test_bearing_closed_form():
    """[e1; e2; e3] = C0ᵀ R(λ_o1)ᵀ(x_p2 − x_p1) − d0 (axial, radial y, radial z, §4.11) and
    e4..e6 equal the HINGE deformations of (o1, o2) about the same axis."""
    c = CASES["BEARING"]
    for off in (False, True):
        for rng, ref, k, x in c.samples("closed", off_sphere=off):
            axis = np.array(ref.params)
            C0 = hinge_frame(axis)
            # R as the quadratic form of §0 (also off the sphere): e_j^{o1} = R(λ_o1) C0 e_j
            pos = (rotation_matrix(x[3:7]) @ C0).T @ (x[7:10] - x[0:3]) - np.array(ref.lgeomy)
            hinge = _testing.element_kernel("HINGE", params=list(axis)).deformations(np.concatenate([x[3:7], x[10:14]]))
            e = k.deformations(x)
            np.testing.assert_allclose(e[:3], pos, atol=TOL * 10)
            np.testing.assert_allclose(e[3:], hinge, atol=TOL)
    assert k.period(3) == 2 * math.pi and k.period(0) == 0.0


def test_bearing_vertical_axis_gives_ground_position_and_yaw():
    """The vehicle use of §4.11/§10.6: a BEARING from the ground (at the origin, λ = 1) with a
    vertical axis has the frame C0 = (z, x, y): e1 = height, e2 = x, e3 = y (minus d0), e4 = yaw ψ
    exactly, e5 = sin φ for a lean φ about the heading, e6 = 0 (no pitch)."""
    k = _testing.element_kernel("BEARING", params=[0, 0, 1], lgeomy=[0.5, 0.0, 0.0])
    for psi, phi in [(0.3, 0.2), (-2.5, -0.7), (3.0, 1.2)]:
        qz = np.array([math.cos(psi / 2), 0, 0, math.sin(psi / 2)])
        qx = np.array([math.cos(phi / 2), math.sin(phi / 2), 0, 0])
        lam = quat_mul(qz, qx)  # yaw, then lean about the body x-axis
        x = np.concatenate([[0, 0, 0], [1, 0, 0, 0], [1.5, -2.0, 0.8], lam])
        np.testing.assert_allclose(k.deformations(x), [0.3, 1.5, -2.0, psi, math.sin(phi), 0.0], atol=TOL)


# ---------------------------------------------------------------------------------------------
# SURFACE
# ---------------------------------------------------------------------------------------------

def quadric_hessian(c):
    return np.array([[2 * c[0], c[3], c[5]], [c[3], 2 * c[1], c[4]], [c[5], c[4], 2 * c[2]]])


def test_surface_closed_form():
    """e1 = c1x² + c2y² + c3z² + c4xy + c5yz + c6zx + c7x + c8y + c9z + c10 (absolute, §4.12);
    B = ∇f, Σσ_iΓ_i = σ1 H with the constant Hessian H, c = vᵀHv."""
    c = CASES["SURFACE"]
    for rng, ref, k, p in c.samples("closed"):
        cf = np.array(ref.params)
        x, y, z = p
        f = cf @ [x * x, y * y, z * z, x * y, y * z, z * x, x, y, z, 1.0]
        H = quadric_hessian(cf)
        grad = H @ p + cf[6:9]
        np.testing.assert_allclose(k.deformations(p), [f], rtol=TOL, atol=TOL)
        np.testing.assert_allclose(k.first_derivatives(p), [grad], rtol=TOL, atol=TOL)
        s = rng.normal()
        np.testing.assert_allclose(k.stress_hessian(p, [s]), s * H, rtol=TOL, atol=TOL)
        np.testing.assert_allclose(k.stress_hessian(rng.normal(size=3), [s]), s * H, rtol=TOL, atol=TOL)
        v = rng.normal(size=3)
        np.testing.assert_allclose(k.convective(p, v), [v @ H @ v], rtol=1e-12, atol=TOL)


def test_surface_sphere_and_plane():
    """Points on the sphere x² + y² + z² = 4 and on the plane x + 2y − z = 3 give e1 = 0."""
    sphere = _testing.element_kernel("SURFACE", params=[1, 1, 1, 0, 0, 0, 0, 0, 0, -4])
    plane = _testing.element_kernel("SURFACE", params=[0, 0, 0, 0, 0, 0, 1, 2, -1, -3])
    rng = np.random.default_rng(3)
    for _ in range(10):
        u = unit(rng.normal(size=3))
        np.testing.assert_allclose(sphere.deformations(2 * u), [0], atol=TOL)
        a, b = rng.normal(size=2)
        np.testing.assert_allclose(plane.deformations(np.array([a, b, a + 2 * b - 3])), [0], atol=TOL)


# ---------------------------------------------------------------------------------------------
# PLWHEEL
# ---------------------------------------------------------------------------------------------

def test_plwheel_slips_are_the_contact_point_velocity():
    """The wheel seen from above (§4.7): a disc of radius r standing on the plane z = 0 with its
    centre above p1, axle a = R(β_o1)â0 (horizontal), spinning at β̇_o2 about a and turning at β̇_o1
    about the vertical. The material velocity of the contact point (directly below the centre),
    v_c = ẋ_p1 + ω × (−r k), ω = β̇_o2 a + β̇_o1 k, computed in 3-D, has the components
    ė1 = t·v_c along t = (a_y, −a_x) and ė2 = a·v_c. Deformation values are not defined (0)."""
    c = CASES["PLWHEEL"]
    kz = np.array([0.0, 0.0, 1.0])
    for rng, ref, k, x in c.samples("contact"):
        r = ref.params[0]
        a2 = rot2(x[2]) @ unit(ref.params[1:3])
        a, t = np.array([*a2, 0.0]), np.array([a2[1], -a2[0], 0.0])
        v = rng.normal(size=4)
        omega = v[3] * a + v[2] * kz
        vc = np.array([v[0], v[1], 0.0]) + np.cross(omega, -r * kz)
        np.testing.assert_allclose(k.rates(x, v), [t @ vc, a @ vc], rtol=1e-13, atol=TOL)
        # convective terms of §4.7: c1 = β̇_o1 (a·ẋ), c2 = −β̇_o1 (t·ẋ)
        np.testing.assert_allclose(k.convective(x, v), [v[2] * (a[:2] @ v[:2]), -v[2] * (t[:2] @ v[:2])],
                                   rtol=1e-13, atol=TOL)
        np.testing.assert_allclose(k.deformations(x), 0.0, atol=0)


def test_plwheel_creep_damping_matrix():
    """EDAMPP d1 d2: σ = diag(d1, d2) ė (released slips, linear creep model)."""
    k = _testing.element_kernel("PLWHEEL", params=[0.3, 0, 1])
    np.testing.assert_array_equal(k.constitutive([40.0, 25.0]), np.diag([40.0, 25.0]))
    assert not k.has_mass


# ---------------------------------------------------------------------------------------------
# WHEEL
# ---------------------------------------------------------------------------------------------

def wheel_data(ref, x):
    axis = unit(ref.params[0:3])
    r = ref.params[3]
    n = unit(ref.params[4:7]) if len(ref.params) == 7 else np.array([0.0, 0.0, 1.0])
    return axis, r, n


def lowest_rim_point(xp, R, axis0, r, n):
    """The rim point with the smallest height n·x. The rim is x_p + r (cos θ b1 + sin θ b2) with
    b1, b2 ⟂ a = R â0; its height n·x_p + r (n·b1 cos θ + n·b2 sin θ) is least at
    θ* = atan2(−n·b2, −n·b1). Checked against a fine sampling of the rim."""
    a = R @ axis0
    b1 = unit(np.cross(a, [1.0, 0.3, -0.2]))
    b2 = np.cross(a, b1)
    th = math.atan2(-(n @ b2), -(n @ b1))
    xc = xp + r * (math.cos(th) * b1 + math.sin(th) * b2)
    samples = np.linspace(0, 2 * math.pi, 3601)
    heights = n @ xp + r * (np.cos(samples) * (n @ b1) + np.sin(samples) * (n @ b2))
    assert n @ xc <= heights.min() + 1e-14 and heights.min() - n @ xc < 1e-6 * r
    return xc


def angular_velocity_fd(lam, lamd):
    """ω from Ṙ Rᵀ = ω~ by differences of R(λ + s λ̇) (λ unit, λ̇ tangent)."""
    Rd = directional_derivative_fd(lambda l: rotation_matrix(l), lam, lamd, 1e-3)
    W = Rd @ rotation_matrix(lam).T
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


@pytest.mark.parametrize("label", ["WHEEL", "WHEEL-n=-z", "WHEEL-n=random"])
def test_wheel_contact_height_and_slips(label):
    """§4.14 against an independent construction: the contact point x_c = the lowest rim point
    (minimised over the rim), e1 = n·x_c (= n·x_p − r s); with the rigid-body velocity field of
    the disc, v_c = ẋ_p + ω × (x_c − x_p), ω from differences of R(λ(t)), the rates are
    ė1 = n·v_c, ė2 = t1·v_c, ė3 = t2·v_c with t1 = (a × n)/|a × n|, t2 = n × t1."""
    c = CASES[label]
    for rng, ref, k, x in c.samples("contact"):
        axis0, r, n = wheel_data(ref, x)
        lam = x[3:7]
        R = rotation_matrix(lam)
        a = R @ axis0
        xc = lowest_rim_point(x[0:3], R, axis0, r, n)
        s = math.sqrt(1 - (n @ a) ** 2)
        e = k.deformations(x)
        np.testing.assert_allclose(e[0], n @ xc, atol=TOL)
        np.testing.assert_allclose(e[0], n @ x[0:3] - r * s, atol=TOL)
        assert e[1] == 0.0 and e[2] == 0.0
        # velocities: λ̇ tangent to the unit sphere
        lamd = rng.normal(size=4)
        lamd -= (lamd @ lam) * lam
        v = np.concatenate([rng.normal(size=3), lamd])
        omega = angular_velocity_fd(lam, lamd)
        np.testing.assert_allclose(omega, 2 * E_of(lam) @ lamd, atol=1e-10)
        vc = v[0:3] + np.cross(omega, xc - x[0:3])
        t1 = unit(np.cross(a, n))
        t2 = np.cross(n, t1)
        np.testing.assert_allclose(k.rates(x, v), [n @ vc, t1 @ vc, t2 @ vc], rtol=0,
                                   atol=1e-10 * max(1, np.abs(v).max()))


def least_rim_point(f, grad, xp, a, r):
    """The rim point where f is least, found without the element's Newton iteration: f sampled
    at 3600 points of the rim, then the root of df/dθ = ∇f·y'(θ) bracketed around the best
    sample (Brent's method)."""
    b1 = unit(np.cross(a, [1.0, 0.3, -0.2]))
    b2 = np.cross(unit(a), b1)
    rho = r * np.linalg.norm(a)
    point = lambda th: xp + rho * (math.cos(th) * b1 + math.sin(th) * b2)
    slope = lambda th: grad(point(th)) @ (rho * (-math.sin(th) * b1 + math.cos(th) * b2))
    grid = np.linspace(0, 2 * math.pi, 3600, endpoint=False)
    best = grid[int(np.argmin([f(point(t)) for t in grid]))]
    h = 2 * math.pi / 3600
    return point(scipy.optimize.brentq(slope, best - h, best + h, xtol=1e-15, rtol=1e-15))


@pytest.mark.parametrize("label", ["WHEEL-ball", "WHEEL-bowl", "WHEEL-ellipsoid"])
def test_wheel_on_a_quadric_contact_height_and_slips(label):
    """§4.14 on a quadratic surface against an independent construction: the contact point y is
    the rim point of least f (sampled and minimised over the rim), e1 = f(y)/|∇f(y)|; the slips
    are t1·v_c and t2·v_c with N = ∇f(y)/|∇f(y)|, t1 = (a × N)/|a × N|, t2 = N × t1 and the
    rigid-body velocity v_c = ẋ_p + ω × (y − x_p) of that rim point."""
    c = CASES[label]
    for rng, ref, k, x in c.samples("contact"):
        Q, b, c0 = quadric_of(ref.params[4:])
        f = lambda y: y @ Q @ y + b @ y + c0
        lam = x[3:7]
        a = rotation_matrix(lam) @ unit(ref.params[0:3])
        y = least_rim_point(f, lambda y: 2 * Q @ y + b, x[0:3], a, ref.params[3])
        g = 2 * Q @ y + b
        e = k.deformations(x)
        np.testing.assert_allclose(e[0], f(y) / np.linalg.norm(g), rtol=0, atol=1e-10 * ref.scale)
        assert e[1] == 0.0 and e[2] == 0.0
        lamd = rng.normal(size=4)
        lamd -= (lamd @ lam) * lam
        v = np.concatenate([rng.normal(size=3), lamd])
        vc = v[0:3] + np.cross(2 * E_of(lam) @ lamd, y - x[0:3])
        n = unit(g)
        t1 = unit(np.cross(a, n))
        t2 = np.cross(n, t1)
        np.testing.assert_allclose(k.rates(x, v)[1:], [t1 @ vc, t2 @ vc], rtol=0,
                                   atol=1e-10 * max(1, np.abs(v).max()))


def test_wheel_on_a_plane_given_as_a_quadric_is_the_plane_wheel():
    """The quadric path with f = n·x (c7..c9 = n) equals the closed-form plane path on the unit
    sphere of λ, where the two formulas describe the same disc (off it they extend it
    differently: the plane formula keeps the radius, the rim R(λ)u0 scales with |λ|²): e, the
    rates B v and the accelerations ë = B ẍ + c along motions that keep |λ| = 1 (λ̇ ⟂ λ,
    λ̈ = −|λ̇|² λ)."""
    rng = np.random.default_rng(11)
    count = 0
    while count < 20:
        axis, r, n = rng.normal(size=3), rng.uniform(0.2, 1.0), unit(rng.normal(size=3))
        plane = _testing.element_kernel("WHEEL", params=[*axis, r, *n])
        quadric = _testing.element_kernel("WHEEL", params=[*axis, r, 0, 0, 0, 0, 0, 0, *n, 0])
        lam = unit(rng.normal(size=4))
        if 1 - (n @ rotation_matrix(lam) @ unit(axis)) ** 2 < 0.09:
            continue
        count += 1
        x = np.concatenate([rng.uniform(-2, 2, 3), lam])
        w = rng.normal(size=4)
        w -= (w @ lam) * lam
        v = np.concatenate([rng.normal(size=3), w])
        acc = np.concatenate([rng.normal(size=3), -(w @ w) * lam])
        for k in (plane, quadric):
            assert np.isfinite(k.deformations(x)).all()
        np.testing.assert_allclose(quadric.deformations(x), plane.deformations(x), rtol=0, atol=1e-13)
        np.testing.assert_allclose(quadric.first_derivatives(x) @ v, plane.first_derivatives(x) @ v,
                                   rtol=0, atol=1e-12 * np.abs(v).max())
        edd = [k.first_derivatives(x) @ acc + k.convective(x, v) for k in (plane, quadric)]
        np.testing.assert_allclose(edd[1], edd[0], rtol=0, atol=1e-11 * max(1.0, np.abs(edd[0]).max()))


def test_wheel_on_a_large_sphere_steeply_tilted():
    """Round-off in the contact search grows like eps/|a × N| for a steeply tilted disc: the
    Newton iteration must accept its round-off floor instead of failing (NaN). A disc of radius 1
    touching spheres of radius 100 and 1e4 at tilts up to 1.54 rad (|a × N| ≈ 0.03), random
    contact directions and spins: e1 ≈ 0 and all derivatives finite."""
    rng = np.random.default_rng(3)
    for R in (100.0, 1e4):
        k = _testing.element_kernel("WHEEL", params=[1, 0, 0, 1.0, 1, 1, 1, 0, 0, 0, 0, 0, 0, -R * R])
        for _ in range(300):
            n = unit(rng.normal(size=3))
            tilt = rng.uniform(1.3, 1.54)
            # axle â0 = x rotated so that its angle with n is π/2 − tilt (tilt 0: upright disc)
            b = unit(np.cross(n, rng.normal(size=3)))
            a = math.cos(tilt) * b + math.sin(tilt) * n
            # λ rotating x onto a, then a random spin about a
            axis = np.cross([1.0, 0, 0], a)
            ang = math.atan2(np.linalg.norm(axis), a[0])
            l1 = np.r_[math.cos(ang / 2), math.sin(ang / 2) * unit(axis)]
            spin = rng.uniform(-math.pi, math.pi)
            l2 = np.r_[math.cos(spin / 2), math.sin(spin / 2) * np.array([1.0, 0, 0])]
            lam = np.r_[l1[0] * l2[0] - l1[1:] @ l2[1:], l1[0] * l2[1:] + l2[0] * l1[1:] + np.cross(l1[1:], l2[1:])]
            d = unit(n - (n @ a) * a)  # from the contact point to the centre, in the disc plane
            x = np.r_[R * n + d, lam]
            e = k.deformations(x)
            assert abs(e[0]) < 1e-9 * R, (R, tilt)
            assert np.isfinite(k.first_derivatives(x)).all() and np.isfinite(k.convective(x, rng.normal(size=7))).all()


def test_wheel_surface_input_errors():
    with pytest.raises(spacar.InputError, match="c1 .. c9 are all zero"):
        _testing.element_kernel("WHEEL", params=[0, 1, 0, 0.3] + [0.0] * 9 + [1.0])
    with pytest.raises(spacar.InputError, match="quadratic surface"):
        _testing.element_kernel("WHEEL", params=[0, 1, 0, 0.3, 1, 1])
    with pytest.raises(spacar.InputError, match=r"^wheel.dat, line 2, keyword WHEEL: WHEEL 1 takes 4, 7 or 14 "
                                                r"numbers after its nodes .* got 10$"):
        spacar.read_string("* a wheel\nWHEEL 1 1 2 0 1 0 0.3 1 1 1 1 1 1\nEND\n", file="wheel.dat")


def test_wheel_rolling_direction():
    """An upright wheel (axle a = +y, ground z = 0, n = +z): t1 = (a × n)/s = +x, t2 = n × t1 = +y.
    Spinning at ω about +y, the bottom point moves at −rω along x, so it rolls without slip at
    ẋ = +rω x: both slips vanish; a unit velocity along x (y) is a unit longitudinal (lateral)
    slip."""
    r = 0.35
    k = _testing.element_kernel("WHEEL", params=[0, 1, 0, r])
    x = np.array([0, 0, r, 1, 0, 0, 0])
    om = 2.0
    lamd = 0.5 * np.array([0, 0, om, 0])  # ω = 2 E(1,0,0,0) λ̇ = (0, ω, 0)
    np.testing.assert_allclose(k.deformations(x), 0.0, atol=TOL)
    np.testing.assert_allclose(k.rates(x, np.concatenate([[r * om, 0, 0], lamd])), 0.0, atol=TOL)
    np.testing.assert_allclose(k.rates(x, np.concatenate([[0, 0, 0], lamd])), [0, -r * om, 0], atol=TOL)
    np.testing.assert_allclose(k.rates(x, np.array([1.0, 0, 0, 0, 0, 0, 0])), [0, 1, 0], atol=TOL)
    np.testing.assert_allclose(k.rates(x, np.array([0, 1.0, 0, 0, 0, 0, 0])), [0, 0, 1], atol=TOL)


# ---------------------------------------------------------------------------------------------
# PLBELT
# ---------------------------------------------------------------------------------------------

def tangent_points(c1, c2, r1, r2):
    """The tangent points of the open belt's free span, found without the element's formula: a
    Newton solve of the tangency conditions (T2 − T1)·(T_i − c_i) = 0 for T_i = c_i + r_i u(θ_i),
    started from the points to the left of the chord; checked afterwards to have both centres on
    the right of the span T1 → T2. Returns T1, T2, θ1, θ2."""
    d = c2 - c1
    th = np.full(2, math.atan2(d[1], d[0]) + 0.5 * math.pi)

    def points(th):
        u1 = np.array([math.cos(th[0]), math.sin(th[0])])
        u2 = np.array([math.cos(th[1]), math.sin(th[1])])
        return u1, u2, c1 + r1 * u1, c2 + r2 * u2

    def conditions(th):
        u1, u2, T1, T2 = points(th)
        return np.array([(T2 - T1) @ u1, (T2 - T1) @ u2])

    converged = False
    for _ in range(30):  # Newton with the exact Jacobian of the two conditions, one polish step
        u1, u2, T1, T2 = points(th)
        w1, w2 = np.array([-u1[1], u1[0]]), np.array([-u2[1], u2[0]])
        J = np.array([[(T2 - T1) @ w1, r2 * w2 @ u1], [-r1 * w1 @ u2, (T2 - T1) @ w2]])
        step = np.linalg.solve(J, conditions(th))
        th = th - step
        if converged:
            break
        converged = np.max(np.abs(step)) < 1e-12
    T1 = c1 + r1 * np.array([math.cos(th[0]), math.sin(th[0])])
    T2 = c2 + r2 * np.array([math.cos(th[1]), math.sin(th[1])])
    s = unit(T2 - T1)
    for ci, Ti in ((c1, T1), (c2, T2)):
        w = ci - Ti
        assert s[0] * w[1] - s[1] * w[0] < 0  # centre on the right of the span
    assert np.max(np.abs(conditions(th))) < 1e-13
    return T1, T2, th[0], th[1]


def nearest_branch(angle, ref):
    return ref + (angle - ref + math.pi) % (2 * math.pi) - math.pi


class BeltGeometry:
    """The belt of a PLBELT reference in configuration x, built from the tangent points: wound
    angles a1 (pulley 1, counter-clockwise from T1 to the material end point carried by the
    pulley) and a2 (pulley 2, clockwise), span T1 → T2, and the belt length between the two
    material end points, r1 a1 + |T2 − T1| + r2 a2."""

    def __init__(self, ref, x):
        r1, r2 = ref.params
        rhoA, a10, a20 = ref.emass
        _, _, th10, th20 = tangent_points(ref.x[0:2], ref.x[3:5], r1, r2)
        self.T1, self.T2, th1, th2 = tangent_points(x[0:2], x[3:5], r1, r2)
        th1, th2 = nearest_branch(th1, th10), nearest_branch(th2, th20)
        # the end point on pulley i sits at θ_i⁰ ± a_i⁰ + β_i (it turns with the pulley)
        self.a1 = (th10 + a10 + x[2]) - th1
        self.a2 = th2 - (th20 - a20 + x[5])
        self.th1, self.th2 = th1, th2
        self.r1, self.r2, self.rhoA = r1, r2, rhoA
        self.c1, self.c2 = x[0:2], x[3:5]
        self.lf = np.linalg.norm(self.T2 - self.T1)
        self.s = (self.T2 - self.T1) / self.lf
        self.length = r1 * self.a1 + self.lf + r2 * self.a2
        L0 = ref.l0
        self.length0 = r1 * a10 + math.sqrt(L0 * L0 - (r2 - r1) ** 2) + r2 * a20

    def material(self, v, weights=40):
        """Gauss-Legendre points along the belt: (position, material velocity, ds) for the arcs
        (rigid with their pulley) and the span (velocity linear between the tangent points)."""
        X, W = np.polynomial.legendre.leggauss(weights)
        xi, w = 0.5 * (X + 1), 0.5 * W
        pts = []
        kx = lambda u: np.array([-u[1], u[0]])  # noqa: E731  (k × u)
        for c, r, om, start, sweep in ((self.c1, self.r1, v[2], self.th1, self.a1),
                                       (self.c2, self.r2, v[5], self.th2 - self.a2, self.a2)):
            cd = v[0:2] if c is self.c1 else v[3:5]
            for q, wq in zip(xi, w):
                phi = start + q * sweep
                u = r * np.array([math.cos(phi), math.sin(phi)])
                pts.append((c + u, cd + om * kx(u), wq * r * sweep))
        v1 = v[0:2] + v[2] * kx(self.T1 - self.c1)
        v2 = v[3:5] + v[5] * kx(self.T2 - self.c2)
        for q, wq in zip(xi, w):
            pts.append((self.T1 + q * (self.T2 - self.T1), (1 - q) * v1 + q * v2, wq * self.lf))
        return pts

    def kinetic(self, v):
        return sum(0.5 * self.rhoA * ds * vel @ vel for _, vel, ds in self.material(v))

    def potential(self, g):
        return -sum(self.rhoA * ds * g[:2] @ p for p, _, ds in self.material(np.zeros(6)))


@pytest.mark.parametrize("label", ["PLBELT", "PLBELT-r1=r2"])
def test_plbelt_length_change_is_e1(label):
    """§10.1: the geometric belt length between the material end points (arcs + span, from the
    independently found tangent points) minus its reference equals e1, at random configurations."""
    c = CASES[label]
    for rng, ref, k, x in c.samples("length"):
        geo = BeltGeometry(ref, x)
        assert geo.a1 > 0 and geo.a2 > 0
        np.testing.assert_allclose(k.deformations(x), [geo.length - geo.length0], atol=1e-12)


@pytest.mark.parametrize("label", ["PLBELT", "PLBELT-r1=r2"])
def test_plbelt_rate_and_convective_closed_forms(label):
    """ė1 = s·(ċ2 − ċ1) + r1β̇1 − r2β̇2 with the span direction s of the tangent points (so e1
    rigid ⇔ this relation), the convective term (u·u − (s·u)²)/l_f with u = ċ2 − ċ1 (§4.6), the
    constitutive σ1 = (EA/l_f0) e1 and the period 2π|r2 − r1| of e1."""
    c = CASES[label]
    for rng, ref, k, x in c.samples("rate"):
        geo = BeltGeometry(ref, x)
        v = rng.normal(size=6)
        u = v[3:5] - v[0:2]
        r1, r2 = ref.params
        np.testing.assert_allclose(k.rates(x, v), [geo.s @ u + r1 * v[2] - r2 * v[5]], atol=1e-12)
        np.testing.assert_allclose(k.convective(x, v), [(u @ u - (geo.s @ u) ** 2) / geo.lf], rtol=1e-10)
        lf0 = math.sqrt(ref.l0**2 - (r2 - r1) ** 2)
        np.testing.assert_allclose(k.constitutive([1234.0]), [[1234.0 / lf0]], rtol=1e-15)
        assert k.period(0) == pytest.approx(2 * math.pi * abs(r2 - r1), rel=1e-15, abs=0)


@pytest.mark.parametrize("label", ["PLBELT", "PLBELT-r1=r2"])
def test_plbelt_kinetic_energy_and_gravity_by_quadrature(label):
    """T = ½ρA ∫|v|² ds and V = −ρA ∫ g·r ds over the belt material (§4.6: wound arcs rigid with
    their pulleys, span velocity linear between the material velocities at the tangent points),
    by Gauss quadrature of the independently constructed belt."""
    c = CASES[label]
    for rng, ref, k, x in c.samples("quadrature"):
        geo = BeltGeometry(ref, x)
        v = rng.normal(size=6)
        g = rng.normal(size=3) * 10
        np.testing.assert_allclose(k.kinetic_energy(x, v), geo.kinetic(v), rtol=1e-12)
        np.testing.assert_allclose(k.gravity_potential(x, g), geo.potential(g), rtol=1e-12,
                                   atol=1e-12 * abs(geo.potential(g)))
        M, _ = k.mass(x, v)
        np.testing.assert_allclose(0.5 * v @ M @ v, geo.kinetic(v), rtol=1e-12)


def test_plbelt_without_emass_has_no_mass():
    k = _testing.element_kernel("PLBELT", params=[0.1, 0.2], l0=1.0, lgeomy=[0.0])
    assert not k.has_mass
    assert k.kinetic_energy(np.array([0, 0, 0.3, 1, 0, 0.2]), np.ones(6)) == 0.0


def test_plbelt_rigid_belt_along_a_motion():
    """§10.1: with e1 rigid, s·(ċ2 − ċ1) + r1β̇1 − r2β̇2 = 0 along the motion — here pulley 1
    driven (INPUTX, accelerating), the centre of pulley 2 moved on a prescribed path (INPUTX
    x and y), pulley 2's rotation calculable from the rigid belt. The relation is checked at
    every output time with s from the tangent points of the simulated positions."""
    r1, r2 = 0.1, 0.25
    m = spacar.Model()
    m.plbelt(1, 1, 2, 3, 4, r1, r2)
    m.xy(1, 0.0, 0.0)
    m.xy(3, 0.7, 0.3)
    m.fix(1)
    m.inputx(2)
    m.xd(2, 1, 3.0)
    m.xdd(2, 1, 5.0)
    m.inputx(3)
    m.xd(3, 1, -0.2)
    m.xd(3, 2, 0.4)
    m.xdd(3, 1, 0.3)
    m.xdd(3, 2, -0.5)
    m.timestep(20, 1.0)
    m.epskin(1e-12)
    res = m.run()
    assert np.max(np.abs(res.deformation(1, 1))) < 1e-12
    for i in range(len(res.t)):
        x, v = res.x[i], res.xd[i]
        T1, T2, _, _ = tangent_points(x[0:2], x[3:5], r1, r2)
        s = unit(T2 - T1)
        relation = s @ (v[3:5] - v[0:2]) + r1 * v[2] - r2 * v[5]
        assert abs(relation) < 1e-12 * max(1.0, np.abs(v).max())
