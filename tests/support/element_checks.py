"""Generic element-level verification (formulation.md §10.1), shared by the element test modules.

An element test module lists its element types as `ElementCase`s (type keyword + random
reference-geometry generator), provides a `case` fixture parametrized over them and derives a
test class from `GenericElementChecks`:

    CASES = [ElementCase("PLTRUSS", chord(2)), ElementCase("PLHINGE", orientations_only), ...]

    @pytest.fixture(params=CASES, ids=str)
    def case(request):
        return request.param

    class TestPlanarElements(GenericElementChecks):
        pass

Every generic check runs at N_CONFIGS random configurations (fixed seed per check and element
type) and compares the kernel's exact (dual-number) derivatives with finite differences:

* B = ∂e/∂x against central differences of e;
* the convective term c = vᵀHv against second differences of e along v;
* Σσ_i H_i against differences of Bᵀσ;
* e invariant under rigid motions, e = 0 at the reference geometry;
* M and h against Lagrange's equations applied to T(x, v) by differences, gravity = −∂V/∂x.

Finite differences are central and Richardson-extrapolated (three levels, error O(h⁶)), so the
truncation error is far below the 1e-7 bound while the steps stay large enough that round-off
(ε/h for first, ε/h² for second differences) is also far below it. Relative errors are
‖A − A_fd‖ / max(‖A‖, 1) (Frobenius norm).

Node kinds: XY, BETA (planar), XYZ, LAMBDA (spatial, unit Euler parameters), so spatial element
types need only their own reference-geometry generator where `chord` does not fit. R(λ) is used
as a quadratic form also off the unit sphere (Newton iterates go there, formulation.md §0), so
for element types with LAMBDA nodes every derivative check is repeated at N_CONFIGS further
configurations whose Euler parameters have random norms in OFF_SPHERE_NORMS. Angle-type
deformations (`ElementCase.angles`, e.g. the HINGE rotation, an atan2 branch) are compared
modulo 2π and differenced on the branch of the base point.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import pytest

from spacar import _core, _testing

NodeKind = _core.NodeKind

N_CONFIGS = 20          # random configurations per check (§10.1: at least 20)
REL_TOL = 1e-7          # bound on relative derivative errors (issue #3)
INVARIANCE_TOL = 1e-12  # absolute bound on e changes under rigid motion, e at the reference

# Finite-difference steps, in units of the coordinate scale (lengths: the element's l0; angles,
# Euler parameters: 1) and, along a velocity, of 1/max|v|. Three Richardson levels h, h/2, h/4
# leave a truncation error O(h⁶); the steps balance it against round-off (ε/h, ε/h²), which
# puts the observed errors of the planar elements near 1e-12 (first), 1e-9 (second differences).
STEP_FIRST = 1e-3     # first differences in x
STEP_SECOND = 1e-2    # second differences in x; x-derivatives of difference quotients
STEP_VELOCITY = 1e-1  # differences of T in v (T is quadratic in v: no truncation error)
RICHARDSON_LEVELS = 3
SYMMETRY_TOL = 1e-13  # ‖A − Aᵀ‖/max(‖A‖, 1) of Hessians and mass matrices (round-off only)
OFF_SPHERE_NORMS = (0.7, 1.4)  # range of |λ| of the off-sphere derivative checks

POSITION_KINDS = (NodeKind.XY, NodeKind.XYZ)
PLANAR_KINDS = (NodeKind.XY, NodeKind.BETA)


# ---------------------------------------------------------------------------------------------
# Finite differences
# ---------------------------------------------------------------------------------------------

def richardson(quotient: Callable[[float], np.ndarray], h: float, levels: int = RICHARDSON_LEVELS):
    """Limit h → 0 of a difference quotient whose error expands in even powers of h, from its
    values at h, h/2, …, h/2^(levels−1) (Richardson/Romberg table)."""
    row = [np.asarray(quotient(h / 2.0**i), dtype=float) for i in range(levels)]
    for j in range(1, levels):
        f = 4.0**j
        row = [(f * row[i + 1] - row[i]) / (f - 1.0) for i in range(len(row) - 1)]
    return row[0]


def jacobian_fd(f, x, steps):
    """∂f/∂x by Richardson-extrapolated central differences; steps[k] is the step of x_k."""
    x = np.asarray(x, dtype=float)
    cols = []
    for k in range(x.size):
        def quotient(h, k=k):
            dx = np.zeros_like(x)
            dx[k] = h
            return (np.asarray(f(x + dx)) - np.asarray(f(x - dx))) / (2.0 * h)
        cols.append(np.atleast_1d(richardson(quotient, steps[k])))
    return np.stack(cols, axis=-1)


def directional_derivative_fd(f, x, v, h):
    """d/dt f(x + t v) at t = 0 (Richardson-extrapolated central differences)."""
    return richardson(lambda s: (np.asarray(f(x + s * v)) - np.asarray(f(x - s * v))) / (2.0 * s), h)


def second_directional_fd(f, x, v, h):
    """d²/dt² f(x + t v) at t = 0: (f(x + hv) − 2f(x) + f(x − hv))/h², Richardson-extrapolated."""
    f0 = np.asarray(f(x))
    return richardson(lambda s: (np.asarray(f(x + s * v)) - 2.0 * f0 + np.asarray(f(x - s * v))) / s**2, h)


def hessian_fd(f, x, steps):
    """Hessian of a scalar function by Richardson-extrapolated central differences of the
    four-point mixed stencil (also exact, up to round-off, for quadratic f)."""
    x = np.asarray(x, dtype=float)
    n = x.size
    H = np.empty((n, n))
    for i in range(n):
        for j in range(i, n):
            def quotient(h, i=i, j=j):
                di = np.zeros(n)
                dj = np.zeros(n)
                di[i] = h * steps[i]
                dj[j] = h * steps[j]
                return (f(x + di + dj) - f(x + di - dj) - f(x - di + dj) + f(x - di - dj)) / (
                    4.0 * h * h * steps[i] * steps[j])
            H[i, j] = H[j, i] = richardson(quotient, 1.0)
    return H


def rel_err(a, b):
    """‖a − b‖ / max(‖a‖, 1), Frobenius norm."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(a), 1.0))


# ---------------------------------------------------------------------------------------------
# Quaternions (Euler parameters, formulation.md §0)
# ---------------------------------------------------------------------------------------------

def skew(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def rotation_matrix(lam):
    """R(λ) = (λ0² − λ̄·λ̄) I + 2 λ̄ λ̄ᵀ + 2 λ0 λ̄~ (body → global), §0."""
    l0, lb = lam[0], np.asarray(lam[1:4])
    return (l0 * l0 - lb @ lb) * np.eye(3) + 2.0 * np.outer(lb, lb) + 2.0 * l0 * skew(lb)


def quat_mul(a, b):
    """Hamilton product; R(a ⊗ b) = R(a) R(b)."""
    a0, av = a[0], np.asarray(a[1:4])
    b0, bv = b[0], np.asarray(b[1:4])
    return np.concatenate([[a0 * b0 - av @ bv], a0 * bv + b0 * av + np.cross(av, bv)])


def random_unit_quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


# ---------------------------------------------------------------------------------------------
# Beam fields (the mass models by quadrature)
# ---------------------------------------------------------------------------------------------

def hermite(xi):
    """The cubic Hermite shape functions on [0, 1] (values at 0 and 1, slopes at 0 and 1)."""
    return np.array([1 - 3 * xi**2 + 2 * xi**3, xi - 2 * xi**2 + xi**3, 3 * xi**2 - 2 * xi**3, -(xi**2) + xi**3])


# Four-point Gauss-Legendre on [0, 1]: exact for the degree-6 polynomials of the Hermite field.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(4)
GAUSS_XI, GAUSS_W = 0.5 * (_GL_X + 1), 0.5 * _GL_W


# ---------------------------------------------------------------------------------------------
# Element cases, reference geometries, configurations
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Reference:
    """Reference geometry of one element: coordinates x with orientations at their reference
    (β = 0, λ = (1,0,0,0)), and the kernel data."""
    x: np.ndarray
    l0: float = 1.0
    lgeomy: tuple = ()
    params: tuple = ()
    emass: tuple = ()
    scale: float = 1.0  # length scale of the position coordinates


@dataclass(frozen=True)
class ElementCase:
    type: str
    reference: Callable[["ElementCase", np.random.Generator], Reference]  # random reference geometry
    label: str = ""        # test id and seed name when one type has several cases (default: type)
    angles: tuple = ()     # 0-based indices of angle-type deformations (atan2 branch, mod 2π)
    # The largest rotation of a LAMBDA node from the reference in the random configurations (None:
    # any): an element whose deformations are angles between its frames and its chord (BEAMC) is
    # singular where they reach π, far from any state of a beam.
    max_rotation: float | None = None

    def __str__(self):
        return self.label or self.type

    @property
    def info(self):
        for t in _core.element_catalogue():
            if t.name == self.type:
                return t
        raise KeyError(self.type)

    @property
    def kinds(self):
        return list(self.info.nodes)

    @property
    def has_emass(self):
        return self.info.n_emass > 0

    def kernel(self, ref: Reference):
        return _testing.element_kernel(self.type, params=list(ref.params), l0=ref.l0,
                                       lgeomy=list(ref.lgeomy), emass=list(ref.emass))

    @property
    def has_lambda(self):
        return NodeKind.LAMBDA in self.kinds

    def rng(self, check: str):
        """Deterministic generator per (element case, check)."""
        return np.random.default_rng(zlib.crc32(f"{self}/{check}".encode()))

    def samples(self, check: str, n: int = N_CONFIGS, off_sphere: bool = False):
        """n tuples (rng, reference, kernel, random configuration x); off_sphere: Euler
        parameters with random norms in OFF_SPHERE_NORMS."""
        rng = self.rng(check + ("@off-sphere" if off_sphere else ""))
        for _ in range(n):
            ref = self.reference(self, rng)
            x = random_configuration(rng, self.kinds, ref, lambda_norms=OFF_SPHERE_NORMS if off_sphere else None,
                                     max_rotation=self.max_rotation)
            yield rng, ref, self.kernel(ref), x

    def derivative_samples(self, check: str):
        """(suffix, samples) for the derivative checks: unit Euler parameters and, for element
        types with LAMBDA nodes, also Euler parameters off the unit sphere."""
        yield "", self.samples(check)
        if self.has_lambda:
            yield "@|λ|≠1", self.samples(check, off_sphere=True)

    def unwrapped(self, k, x):
        """The kernel k with its angle-type deformations taken on the branch of their values at
        x (so that differences about x do not jump by 2π); k itself without angles."""
        return _Unwrapped(k, self.angles, k.deformations(x)) if self.angles else k


def wrap_to_pi(a):
    """a reduced to [−π, π)."""
    return (np.asarray(a) + math.pi) % (2.0 * math.pi) - math.pi


class _Unwrapped:
    def __init__(self, k, angles, e0):
        self._k, self._angles, self._e0 = k, list(angles), np.asarray(e0)

    def deformations(self, x):
        e = np.array(self._k.deformations(x))
        a = self._angles
        e[a] = self._e0[a] + wrap_to_pi(e[a] - self._e0[a])
        return e

    def __getattr__(self, name):
        return getattr(self._k, name)


def node_slices(kinds: Sequence) -> list:
    out, i = [], 0
    for k in kinds:
        n = _core.node_size(k)
        out.append(slice(i, i + n))
        i += n
    return out


def assemble(kinds, positions):
    """Coordinate vector with the position nodes at `positions` (in node order) and every
    orientation node at its reference."""
    positions = iter(positions)
    parts = []
    for k in kinds:
        if k in POSITION_KINDS:
            parts.append(np.asarray(next(positions), dtype=float))
        elif k == NodeKind.BETA:
            parts.append(np.zeros(1))
        elif k == NodeKind.LAMBDA:
            parts.append(np.array([1.0, 0.0, 0.0, 0.0]))
        else:
            raise NotImplementedError(f"node kind {k}")
    return np.concatenate(parts)


def coordinate_scales(kinds, ref: Reference):
    """Scale of each coordinate (lengths: ref.scale; angles and Euler parameters: 1)."""
    return np.concatenate([np.full(_core.node_size(k), ref.scale if k in POSITION_KINDS else 1.0)
                           for k in kinds])


def chord(case: ElementCase, rng) -> Reference:
    """Two position nodes a random distance l0 ∈ [0.5, 2] apart in a random direction (planar:
    chord angle α0 ∈ [−π, π], passed as LGEOMY when the type takes it), random ρA ∈ [0.5, 3]."""
    kinds = case.kinds
    dim = _core.node_size(next(k for k in kinds if k in POSITION_KINDS))
    l0 = rng.uniform(0.5, 2.0)
    p = rng.uniform(-2.0, 2.0, size=dim)
    if dim == 2:
        alpha0 = rng.uniform(-math.pi, math.pi)
        d = np.array([math.cos(alpha0), math.sin(alpha0)])
        lgeomy = (alpha0,) if case.info.n_lgeomy == 1 else ()
    else:
        d = rng.normal(size=dim)
        d /= np.linalg.norm(d)
        lgeomy = ()
    emass = (rng.uniform(0.5, 3.0),) if case.has_emass else ()
    return Reference(x=assemble(kinds, [p, p + l0 * d]), l0=l0, lgeomy=lgeomy, emass=emass, scale=l0)


def orientations_only(case: ElementCase, rng) -> Reference:
    """Elements connecting orientation nodes only (hinges): reference = all orientations at
    their reference."""
    return Reference(x=assemble(case.kinds, []))


def random_configuration(rng, kinds, ref: Reference, spread: float = 0.2, lambda_norms=None, max_rotation=None):
    """Position nodes moved independently by up to ±spread·scale per component from the
    reference (for a chord this keeps l ≥ (1 − 2√2·spread) l0); BETA uniform in [−π, π];
    LAMBDA random unit Euler parameters (with max_rotation: a rotation about a random axis by at
    most that angle), or, with lambda_norms = (lo, hi), random Euler parameters of norm uniform
    in [lo, hi]."""
    x = np.array(ref.x, dtype=float)
    for k, s in zip(kinds, node_slices(kinds)):
        if k in POSITION_KINDS:
            x[s] += rng.uniform(-spread, spread, size=s.stop - s.start) * ref.scale
        elif k == NodeKind.BETA:
            x[s] = rng.uniform(-math.pi, math.pi)
        elif k == NodeKind.LAMBDA:
            if max_rotation is None:
                x[s] = random_unit_quaternion(rng)
            else:
                axis, angle = rng.normal(size=3), rng.uniform(0.0, max_rotation)
                x[s] = np.r_[math.cos(angle / 2), math.sin(angle / 2) * axis / np.linalg.norm(axis)]
            if lambda_norms is not None:
                x[s] *= rng.uniform(*lambda_norms)
        else:
            raise NotImplementedError(f"node kind {k}")
    return x


def random_rigid_motion(rng, kinds, scale=1.0):
    """A random rigid motion as a function x ↦ x′ on the element's coordinates. Planar: rotation
    by θ about a random point, translation; every BETA gets + θ. Spatial: rotation Q = R(q) about
    a random point, translation; every LAMBDA λ ↦ q ⊗ λ (so R(λ′) = Q R(λ)); a BETA node of a
    spatial element is a scalar of its own (BEAMW's rates of twist), unchanged."""
    slices = node_slices(kinds)
    planar = all(k in PLANAR_KINDS for k in kinds)
    dim = 2 if planar else 3
    centre = rng.uniform(-3.0, 3.0, size=dim) * scale
    shift = rng.uniform(-3.0, 3.0, size=dim) * scale
    if planar:
        theta = rng.uniform(-math.pi, math.pi)
        Q = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    else:
        q = random_unit_quaternion(rng)
        Q = rotation_matrix(q)

    def move(x):
        y = np.array(x, dtype=float)
        for k, s in zip(kinds, slices):
            if k in POSITION_KINDS:
                y[s] = centre + Q @ (x[s] - centre) + shift
            elif k == NodeKind.BETA:
                y[s] = x[s] + theta if planar else x[s]
            elif k == NodeKind.LAMBDA:
                y[s] = quat_mul(q, x[s])
            else:
                raise NotImplementedError(f"node kind {k}")
        return y

    return move


# ---------------------------------------------------------------------------------------------
# The checks (each returns the relative error of one configuration)
# ---------------------------------------------------------------------------------------------

def first_derivative_error(k, x, scales):
    B = k.first_derivatives(x)
    return rel_err(B, jacobian_fd(k.deformations, x, STEP_FIRST * scales))


def convective_error(k, x, v):
    c = k.convective(x, v)
    h = STEP_SECOND / np.max(np.abs(v))
    return rel_err(c, second_directional_fd(k.deformations, x, v, h))


def stress_hessian_error(k, x, sigma, scales):
    G = k.stress_hessian(x, sigma)
    G_fd = jacobian_fd(lambda y: k.first_derivatives(y).T @ sigma, x, STEP_FIRST * scales)
    return rel_err(G, G_fd)


def mass_matrix_error(k, x, v, scales):
    """M against ∂²T/∂v² by differences."""
    M, _ = k.mass(x, v)
    M_fd = hessian_fd(lambda w: k.kinetic_energy(x, w), v, STEP_VELOCITY * scales)
    return rel_err(M, M_fd)


def convective_inertia_error(k, x, v, scales):
    """h against Lagrange: h = (∂²T/∂v∂x) v − ∂T/∂x, every derivative by differences."""
    _, h = k.mass(x, v)
    ev = np.eye(v.size)

    def momentum(y):  # ∂T/∂v at (y, v)
        return np.array([directional_derivative_fd(lambda w: k.kinetic_energy(y, w), v, ev[i],
                                                   STEP_VELOCITY * scales[i]) for i in range(v.size)])

    # (∂p/∂x) v = d/ds p(x + s v): a derivative of a difference quotient, hence the larger step
    dp = directional_derivative_fd(momentum, x, v, STEP_SECOND * np.min(scales) / np.max(np.abs(v)))
    dTdx = jacobian_fd(lambda y: np.array([k.kinetic_energy(y, v)]), x, STEP_FIRST * scales)[0]
    return rel_err(h, dp - dTdx)


def gravity_error(k, x, g, scales):
    f = k.gravity(x, g)
    dV = jacobian_fd(lambda y: np.array([k.gravity_potential(y, g)]), x, STEP_FIRST * scales)[0]
    return rel_err(f, -dV)


@pytest.fixture
def record(record_property):
    """record(case, check, worst): keep the worst error of a check (junit property, and printed:
    `pytest -rP` shows them)."""
    def rec(case, check, value):
        record_property(f"{case}/{check}", value)
        print(f"{case} {check}: worst {value:.3e}")
    return rec


class GenericElementChecks:
    """Generic §10.1 checks; a test module subclasses this, defines a `case` fixture
    and imports the `record` fixture. The derivative checks run at unit Euler parameters and,
    for element types with LAMBDA nodes, also off the unit sphere (recorded as `check@|λ|≠1`).
    A subclass may replace the two error measures (e.g. for velocity-level rows)."""

    first_derivative_error = staticmethod(first_derivative_error)

    @staticmethod
    def convective_error(case, k, x, v):
        return convective_error(k, x, v)

    def test_first_derivatives_match_differences(self, case, record):
        worst_all = 0.0
        for suffix, samples in case.derivative_samples("B"):
            worst = 0.0
            for _, ref, k, x in samples:
                worst = max(worst, self.first_derivative_error(case.unwrapped(k, x), x,
                                                               coordinate_scales(case.kinds, ref)))
            record(case, "B" + suffix, worst)
            worst_all = max(worst_all, worst)
        assert worst_all < REL_TOL

    def test_convective_term_matches_second_differences(self, case, record):
        worst_all = 0.0
        for suffix, samples in case.derivative_samples("c"):
            worst = 0.0
            for rng, ref, k, x in samples:
                v = rng.normal(size=x.size) * coordinate_scales(case.kinds, ref)
                worst = max(worst, self.convective_error(case, case.unwrapped(k, x), x, v))
            record(case, "c" + suffix, worst)
            worst_all = max(worst_all, worst)
        assert worst_all < REL_TOL

    def test_stress_hessian_matches_differences(self, case, record):
        worst_all = 0.0
        for suffix, samples in case.derivative_samples("G"):
            worst = 0.0
            for rng, ref, k, x in samples:
                sigma = rng.normal(size=k.n_deformations)
                G = k.stress_hessian(x, sigma)
                assert rel_err(G, G.T) < SYMMETRY_TOL
                worst = max(worst, stress_hessian_error(k, x, sigma, coordinate_scales(case.kinds, ref)))
            record(case, "G" + suffix, worst)
            worst_all = max(worst_all, worst)
        assert worst_all < REL_TOL

    def test_deformations_invariant_under_rigid_motion(self, case, record):
        worst = 0.0
        for rng, ref, k, x in case.samples("rigid"):
            move = random_rigid_motion(rng, case.kinds, ref.scale)
            d = k.deformations(move(x)) - k.deformations(x)
            d[list(case.angles)] = wrap_to_pi(d[list(case.angles)])
            worst = max(worst, float(np.max(np.abs(d))))
        record(case, "rigid", worst)
        assert worst < INVARIANCE_TOL

    def test_deformations_vanish_at_reference(self, case, record):
        worst = 0.0
        for rng, ref, k, _ in case.samples("ref"):
            move = random_rigid_motion(rng, case.kinds, ref.scale)
            worst = max(worst, float(np.max(np.abs(k.deformations(ref.x)))),
                        float(np.max(np.abs(k.deformations(move(ref.x))))))
        record(case, "e_ref", worst)
        assert worst < INVARIANCE_TOL

    def test_mass_matches_lagrange_equations(self, case, record):
        worst_M = worst_h = 0.0
        for suffix, samples in case.derivative_samples("mass"):
            wM = wh = 0.0
            for rng, ref, k, x in samples:
                v = rng.normal(size=x.size) * coordinate_scales(case.kinds, ref)
                M, h = k.mass(x, v)
                if not case.has_emass:  # no distributed mass: everything vanishes
                    assert not k.has_mass
                    assert not M.any() and not h.any() and k.kinetic_energy(x, v) == 0.0
                    continue
                assert k.has_mass
                assert rel_err(M, M.T) < SYMMETRY_TOL
                assert np.min(np.linalg.eigvalsh(0.5 * (M + M.T))) > -1e-12 * np.max(np.abs(M))
                scales = coordinate_scales(case.kinds, ref)
                wM = max(wM, mass_matrix_error(k, x, v, scales))
                wh = max(wh, convective_inertia_error(k, x, v, scales))
            record(case, "M" + suffix, wM)
            record(case, "h" + suffix, wh)
            worst_M, worst_h = max(worst_M, wM), max(worst_h, wh)
        assert worst_M < REL_TOL
        assert worst_h < REL_TOL

    def test_gravity_is_minus_potential_gradient(self, case, record):
        worst_all = 0.0
        for suffix, samples in case.derivative_samples("gravity"):
            worst = 0.0
            for rng, ref, k, x in samples:
                g = rng.normal(size=3) * 10.0
                if not case.has_emass:
                    assert not k.gravity(x, g).any() and k.gravity_potential(x, g) == 0.0
                    continue
                worst = max(worst, gravity_error(k, x, g, coordinate_scales(case.kinds, ref)))
                # The combined call of every right-hand side: the same numbers as the two calls.
                v = rng.normal(size=x.size)
                M, h, f = k.mass_and_gravity(x, v, g)
                M1, h1 = k.mass(x, v)
                assert rel_err(M, M1) < 1e-14 and rel_err(h, h1) < 1e-14 and rel_err(f, k.gravity(x, g)) < 1e-14
            record(case, "gravity" + suffix, worst)
            worst_all = max(worst_all, worst)
        assert worst_all < REL_TOL
