"""Validation of spatial mechanisms (issue #4 "Must show"; formulation.md §3.2, §3.4, §4.8–4.10,
§4.13, §8, §10.2, §10.3, §10.5).

* The manual's slider-crank rebuilt with XYZ/LAMBDA nodes, BEAM and HINGE elements
  (examples/slidercrank3d.dat) equals the planar run at every output time.
* Rigid bodies on LAMBDA nodes: a torque-free asymmetric body (energy, angular momentum, the
  period of the intermediate-axis flip against Landau–Lifshitz §37), a body with a body-fixed
  torque (TORQUEL) against Euler's equations, a free-flying rigid BEAM with rotary inertia
  (momenta, energy), and the steady precession of a heavy symmetric top (point mass with a
  rigid body on a rigid BEAM; a uniform BEAM rod with its own gravity load); a torsional
  oscillator on a skew HINGE and a conical pendulum on a TRUSS.
* A BEAM cantilever: bending in both planes (formulation.md §10.3 table) and torsion (converging
  from above at second order, exactly the discrete dispersion relation of linear elements).
* A spatial four-bar (RSSR and RSUR) driven kinematically (closed-form loop solution) and free
  under gravity for 10 s (unit Euler parameters, loop closure, energy).
"""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eigh
from scipy.special import ellipk

import spacar
from spacar import cli
from support.manual import printed_state, values
from support.simulation import assembled
from support.spatial_models import (
    PLANAR_EXAMPLE,
    RSSR,
    SPATIAL_EXAMPLE,
    E_,
    G_,
    R_,
    body_angular_velocity,
    cantilever,
    lambda_nodes,
    linearize,
    rssr_model,
    tighten,
)


# =============================================================================================
# Slider-crank: 3-D rebuild = planar run
# =============================================================================================

@pytest.fixture(scope="module")
def slidercrank_runs():
    spatial = tighten(spacar.read(SPATIAL_EXAMPLE))
    planar = tighten(spacar.read(PLANAR_EXAMPLE))
    return spacar.simulate(spatial), spacar.simulate(planar)


def z_rotation_angle(lam):
    """Rotation angle about z of Euler parameters that rotate about z only, made continuous."""
    return np.unwrap(2.0 * np.arctan2(lam[:, 3], lam[:, 0]))


def test_slidercrank_3d_equals_planar_run(slidercrank_runs):
    """Tight tolerances on both runs (EPSINT = EPSIND = 1e-11, EPSKIN = 1e-12); at all 101
    output times: positions and velocities, BETA ↔ hinge angle / Euler-parameter angles, and
    BEAM e5, e6 = PLBEAM e2, e3 with their rates and accelerations, to 1e-8 (E relative to its
    magnitude). The motion stays in the plane: z, the out-of-plane Euler parameters and the
    other beam deformations are zero."""
    sp, pl = slidercrank_runs
    np.testing.assert_array_equal(sp.t, pl.t)
    assert len(sp.t) == 101 and sp.t[-1] == 5.0
    for n in (1, 3, 6, 8):
        np.testing.assert_allclose(sp.node(n).x[:, :2], pl.node(n).x, rtol=0, atol=1e-8)
        np.testing.assert_allclose(sp.node(n).xd[:, :2], pl.node(n).xd, rtol=0, atol=1e-8)
        np.testing.assert_array_equal(sp.node(n).x[:, 2], 0.0)
    # Crank: hinge 4 e1 (multi-turn, unwrapped by the engine) is the input angle β2.
    np.testing.assert_allclose(sp.deformation(4, 1), pl.coordinate(2, 1), rtol=0, atol=1e-8)
    np.testing.assert_allclose(sp.element(4).ed[:, 0], pl.node(2).xd[:, 0], rtol=0, atol=1e-8)
    assert sp.deformation(4, 1)[-1] == pytest.approx(7.5, abs=1e-12)
    # Every BETA node of the planar run is a LAMBDA node rotating about z.
    for n in (2, 4, 5, 7, 9):
        lam = sp.node(n).x
        np.testing.assert_allclose(z_rotation_angle(lam), pl.coordinate(n, 1), rtol=0, atol=1e-8)
        np.testing.assert_allclose(lam[:, 1:3], 0.0, rtol=0, atol=1e-15)
    for attr in ("e", "ed", "edd"):
        scale = max(np.abs(getattr(pl.element(e), attr)[:, 1:]).max() for e in (2, 3))
        for e in (1, 2, 3):  # element 1 (the crank) is rigid: its E are zero in both runs
            s, p = getattr(sp.element(e), attr), getattr(pl.element(e), attr)
            np.testing.assert_allclose(s[:, 4:6], p[:, 1:3], rtol=0, atol=1e-8 * scale)
            np.testing.assert_allclose(s[:, 1:4], 0.0, rtol=0, atol=1e-12)
    # The flexible rod really deforms (the comparison is not trivially of zeros).
    assert np.abs(pl.element(2).e[:, 1:]).max() > 1e-3


# The manual's printed state at t = 5 s (section 5.7): positions of nodes 3, 6, 8 (same numbers
# in the 3-D model) and E (2,2), (2,3), (3,2), (3,3) of the PLBEAMs = BEAM e5, e6.
_MANUAL_X, _MANUAL_E = values(printed_state(), "XY"), values(printed_state(), "E")
MANUAL_DUMP = {
    "positions": {n: (_MANUAL_X[(n, 1)], _MANUAL_X[(n, 2)]) for n in (3, 6, 8)},
    "E": {(e, i + 3): _MANUAL_E[(e, i)] for e in (2, 3) for i in (2, 3)},
}


def test_slidercrank3d_example_runs_with_spacar_run(capsys):
    """`spacar run examples/slidercrank3d.dat` (the manual's settings, EPSINT = 1e-3) prints a
    dump whose positions match the manual's printed ones to one unit of the last digit and whose
    E (BEAM e5, e6) match the manual's PLBEAM E within 0.5 % (formulation.md §10.5); the dump is
    valid input and continues the run."""
    assert cli.main(["run", str(SPATIAL_EXAMPLE)]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if line and not line.startswith("*")]
    xyz = {int(r[1]): [float(v) for v in r[2:]] for r in rows if r[0] == "XYZ"}

    def one_unit(v):  # of the last digit of %10.3E
        return 1.001e-3 * 10.0 ** math.floor(math.log10(abs(v))) if v else 0.0

    for n, (x, y) in MANUAL_DUMP["positions"].items():
        assert abs(xyz[n][0] - x) <= one_unit(x), (n, xyz[n], x)
        assert abs(xyz[n][1] - y) <= one_unit(y), (n, xyz[n], y)
        assert xyz[n][2] == 0.0
    E = {(int(r[1]), int(r[2])): float(r[3]) for r in rows if r[0] == "E"}
    for key, value in MANUAL_DUMP["E"].items():
        assert E[key] == pytest.approx(value, rel=5e-3)
    assert E[(4, 1)] == pytest.approx(7.5)
    model = spacar.read_string(out, "dump.dat")
    res = spacar.simulate(model)
    assert res.t[0] == 5.0 and res.t[-1] == 10.0


def test_fully_fixed_lambda_nodes_of_the_example_are_legal():
    """The ground orientations 10 and 11 are fully fixed (FIX n): their L2MIN1 rows are
    checked instead of solved (formulation.md §1.3), and the run proceeds."""
    model = spacar.read(SPATIAL_EXAMPLE)
    res = spacar.simulate(model)
    for n in (10, 11):
        np.testing.assert_array_equal(res.node(n).x, np.tile([1.0, 0.0, 0.0, 0.0], (len(res.t), 1)))
    np.testing.assert_array_equal(res.e[:, [res.deformation_index(e, 1) for e in (12, 13)]], 0.0)


# =============================================================================================
# Rigid bodies on LAMBDA nodes
# =============================================================================================

def free_body(J, lam0, w0, period, n_out, torque=None, dynx=()):
    """A rigid body on LAMBDA node 1 with body inertia J, free rotation, initial body angular
    velocity w0 given through λ̇ = ½ G(λ)ᵀ ω′."""
    m = spacar.Model()
    m.lambda_(1, *lam0)
    m.mass(1, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
    m.dynx(1, *dynx)
    if torque is not None:
        m.torquel(1, *torque)
    for i, v in enumerate(0.5 * G_(lam0).T @ w0):
        m.xd(1, i + 1, v)
    m.timestep(n_out, period)
    return tighten(m)


LAM0 = np.array([0.8, 0.3, -0.4, 0.33]) / np.linalg.norm([0.8, 0.3, -0.4, 0.33])


def landau_lifshitz_period(I, T, H2):
    """Period of ω(t) of the torque-free body, I1 < I2 < I3 (Landau–Lifshitz §37):
    T = 4K(k)/ω_p, for M² > 2EI2 with k² = (I2−I1)(2EI3−M²)/((I3−I2)(M²−2EI1)),
    ω_p² = (I3−I2)(M²−2EI1)/(I1I2I3); for M² < 2EI2 the indices 1 and 3 are interchanged."""
    I1, I2, I3 = I
    E2 = 2.0 * T
    if H2 > E2 * I2:
        k2 = (I2 - I1) * (E2 * I3 - H2) / ((I3 - I2) * (H2 - E2 * I1))
        wp = math.sqrt((I3 - I2) * (H2 - E2 * I1) / (I1 * I2 * I3))
    else:
        k2 = (I3 - I2) * (H2 - E2 * I1) / ((I2 - I1) * (E2 * I3 - H2))
        wp = math.sqrt((I2 - I1) * (E2 * I3 - H2) / (I1 * I2 * I3))
    assert 0.0 < k2 < 1.0
    return 4.0 * ellipk(k2) / wp


def zero_crossings(t, f, fd):
    """Zero crossings of f, located on the cubic Hermite interpolant of (f, ḟ) in each output
    interval (error O(Δt⁴), unlike linear interpolation)."""
    roots = []
    for i in np.nonzero(f[:-1] * f[1:] < 0)[0]:
        h = t[i + 1] - t[i]
        # Hermite cubic in s ∈ [0, 1]; its coefficients, then the root inside the interval.
        p0, p1, m0, m1 = f[i], f[i + 1], h * fd[i], h * fd[i + 1]
        coeffs = [2 * p0 - 2 * p1 + m0 + m1, -3 * p0 + 3 * p1 - 2 * m0 - m1, m0, p0]
        s = [r.real for r in np.roots(coeffs) if abs(r.imag) < 1e-9 and -1e-12 <= r.real <= 1 + 1e-12]
        assert len(s) == 1
        roots.append(t[i] + h * s[0])
    return np.array(roots)


@pytest.mark.parametrize("w0", [(0.3, 1.0, 0.3), (0.3, 1.0, 0.1)], ids=["H2>2EI2", "H2<2EI2"])
def test_torque_free_asymmetric_body(w0):
    """J′ = diag(1, 2, 3), spin mostly about the intermediate axis, general initial orientation,
    100 s at EPSINT = EPSIND = 1e-11, EPSKIN = 1e-12 (the free rotation passes through many
    re-partitions of the dependent Euler parameter). Energy and the global angular momentum
    vector H = R(λ) J′ ω′ are conserved to 1e-9 (relative), and the period of ω′(t), twice the
    spacing of the zero crossings of ω′2 ∝ sn, matches 4K(k)/ω_p to 1e-8 (issue: ~1e-6).
    Both branches of the formula (M² above and below 2EI2) are covered."""
    I = np.array([1.0, 2.0, 3.0])
    res = spacar.simulate(free_body(np.diag(I), LAM0, np.array(w0), 100.0, 10000))
    lam, lamd, lamdd = res.node(1).x, res.node(1).xd, res.node(1).xdd
    w = body_angular_velocity(lam, lamd)
    wd = body_angular_velocity(lam, lamdd)  # d/dt(2Gλ̇) = 2Gλ̈ because G(λ̇)λ̇ = 0
    T = 0.5 * np.einsum("ti,i,ti->t", w, I, w)
    H = np.array([R_(l) @ (I * wi) for l, wi in zip(lam, w)])
    np.testing.assert_allclose(np.abs((lam**2).sum(axis=1) - 1.0).max(), 0.0, atol=1e-12)
    signs = np.sign(lam)  # every Euler parameter passes through zero: re-partitions happen
    assert all(np.count_nonzero(np.diff(signs[:, i])) >= 10 for i in range(4))
    assert np.abs(T / T[0] - 1.0).max() < 1e-9
    assert np.abs(H - H[0]).max() / np.linalg.norm(H[0]) < 1e-9
    assert np.allclose(w[0], w0, rtol=0, atol=1e-12)
    period = landau_lifshitz_period(I, T[0], H[0] @ H[0])
    crossings = zero_crossings(res.t, w[:, 1], wd[:, 1])
    assert len(crossings) >= 10  # the body flips many times
    half_period = np.polyfit(np.arange(len(crossings)), crossings, 1)[0]
    assert abs(2.0 * half_period / period - 1.0) < 1e-8
    # The flip: ω′2 ∝ sn(τ, k) swings between ± its amplitude in both branches.
    assert w[:, 1].max() > 0.5 and w[:, 1].min() < -0.5


def test_torquel_body_matches_euler_equations():
    """Full inertia tensor (products of inertia), body-fixed torque (TORQUEL, follower load
    2Gᵀ T′) and a general initial state: λ(t) and ω′(t) agree with an independent integration
    of J′ω̇′ + ω′ × J′ω′ = T′, λ̇ = ½ G(λ)ᵀ ω′ (formulation.md §3.2, §3.4) to 1e-9. The result
    does not depend on whether all four or three Euler parameters are declared DYNX."""
    J = np.array([[2.0, 0.1, -0.2], [0.1, 3.0, 0.3], [-0.2, 0.3, 4.0]])
    torque, w0 = np.array([0.3, -0.2, 0.5]), np.array([0.5, -1.0, 2.0])
    lam0 = np.array([0.6, -0.2, 0.5, 0.4]) / np.linalg.norm([0.6, -0.2, 0.5, 0.4])

    def rhs(t, y):
        lam, w = y[:4], y[4:]
        return np.concatenate([0.5 * G_(lam).T @ w, np.linalg.solve(J, torque - np.cross(w, J @ w))])

    t_out = np.linspace(0.0, 10.0, 201)
    ref = solve_ivp(rhs, (0.0, 10.0), np.concatenate([lam0, w0]), method="DOP853", rtol=1e-13,
                    atol=1e-14, t_eval=t_out)
    for dynx in ((), (2, 3, 4)):
        res = spacar.simulate(free_body(J, lam0, w0, 10.0, 200, torque=torque, dynx=dynx))
        np.testing.assert_allclose(res.t, t_out, rtol=0, atol=1e-12)
        w = body_angular_velocity(res.node(1).x, res.node(1).xd)
        np.testing.assert_allclose(w, ref.y[4:].T, rtol=0, atol=1e-9)
        np.testing.assert_allclose(res.node(1).x, ref.y[:4].T, rtol=0, atol=1e-9)
        # Every Euler parameter changes sign: rotations through 180° about several axes, so the
        # dependent parameter of the free rotation is re-partitioned during the run.
        signs = np.sign(res.node(1).x)
        assert all(np.count_nonzero(np.diff(signs[:, i])) >= 2 for i in range(4))


def test_free_flying_rigid_beam_conserves_momenta_and_energy():
    """A rigid BEAM (all deformations fixed) flying freely: its XYZ node p and LAMBDA node are
    DYNX (6 DOF, free rotation), EMASS ρA with rotary inertia ρIp ρIy ρIz (extension). For a
    straight rigid beam the Hermite interpolation is the exact rigid rod r = x_p + s t, and the
    section inertia integrates to l0 J_s about the body axes, so
        P = ρA l0 (ẋ_p + ½ l0 ṫ),
        H = ρA (l0 x_p×ẋ_p + ½l0² (x_p×ṫ + t×ẋ_p) + ⅓l0³ t×ṫ) + R(λ) l0 J_s ω′,
        T = ½ρA l0 (|ẋ_p|² + l0 ẋ_p·ṫ + ⅓l0²|ṫ|²) + ½ l0 ω′ᵀJ_s ω′
    are conserved (20 s, general initial translation and rotation, EPSINT = EPSIND = 1e-11)."""
    rho_a, js, l0 = 2.0, np.array([0.02, 0.01, 0.03]), 1.2
    lam0 = np.array([0.9, 0.2, -0.3, 0.25]) / np.linalg.norm([0.9, 0.2, -0.3, 0.25])
    w0, v0 = np.array([0.4, -1.5, 2.0]), np.array([0.3, -0.2, 0.5])  # global ω, velocity of p
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 4, 0.0, 1.0, 0.0)
    m.x(3, l0, 0.0, 0.0)
    m.x(2, *lam0)
    m.x(4, *lam0)
    m.dynx(1)
    m.dynx(2)
    for i in range(3):
        m.xd(1, i + 1, v0[i])
    for i, v in enumerate(0.5 * E_(lam0).T @ w0):
        m.xd(2, i + 1, v)
    m.emass(1, rho_a, *js)
    m.timestep(500, 20.0)
    res = spacar.simulate(tighten(m))
    xp, xq, vp, vq = res.node(1).x, res.node(3).x, res.node(1).xd, res.node(3).xd
    lam, lamd = res.node(2).x, res.node(2).xd
    np.testing.assert_allclose(np.linalg.norm(xq - xp, axis=1), l0, rtol=0, atol=1e-12)
    t, td = (xq - xp) / l0, (vq - vp) / l0
    w = body_angular_velocity(lam, lamd)
    np.testing.assert_allclose(R_(lam[0]) @ w[0], w0, rtol=0, atol=1e-12)
    P = rho_a * l0 * (vp + 0.5 * l0 * td)
    H = rho_a * (l0 * np.cross(xp, vp) + 0.5 * l0**2 * (np.cross(xp, td) + np.cross(t, vp))
                 + l0**3 / 3 * np.cross(t, td))
    H += np.array([R_(lk) @ (l0 * js * wk) for lk, wk in zip(lam, w)])
    T = 0.5 * rho_a * l0 * ((vp**2).sum(1) + l0 * (vp * td).sum(1) + l0**2 / 3 * (td**2).sum(1))
    T += 0.5 * l0 * np.einsum("ti,i,ti->t", w, js, w)
    assert np.abs(P - P[0]).max() / np.linalg.norm(P[0]) < 1e-9
    assert np.abs(H - H[0]).max() / np.linalg.norm(H[0]) < 1e-9
    assert np.abs(T / T[0] - 1.0).max() < 1e-9
    assert np.abs(w).max() > 2.0 and np.ptp(xp, axis=0).min() > 1.0  # it tumbles and travels


class Top:
    """Heavy symmetric top on a fixed point, two equivalent constructions:

    * "point mass": XYZ node 1 fixed (the pivot), BEAM 1 from (1, λ2) to the centre of mass
      (3, λ4), rigid (all six deformations fixed, no EMASS), λ2 DYNX (free rotation); MASS m on
      node 3 (it carries the gravity load), MASS J_cm = diag(Jt, Jt, Ja) on λ4 (inertia about
      the centre of mass in the body frame; symmetry axis = beam axis = body z). About the
      pivot I1 = Jt + m l², I3 = Ja, m g l with l the distance to node 3.
    * "uniform rod": the same rigid BEAM with distributed mass and rotary inertia
      (EMASS ρA ρIp ρIy ρIy) instead of MASS — gravity then acts through the BEAM's mass model
      (formulation.md §4.8: ½ρAl0 g on the nodes, (ρAl0²/12) T_{e_x0}ᵀ g on the orientations).
      I1 = ρA L³/3 + ρIy L, I3 = ρIp L, m g l = ρA L g L/2.

    Steady precession (Euler angles φ precession, θ nutation from the upward vertical, ψ spin):
    the θ equation I1θ̈ = sin θ (I1 φ̇² cos θ − I3 ω3 φ̇ + m g l) vanishes for φ̇ = Ω with
    m g l = Ω (I3 ω3 − I1 Ω cos θ), ω3 = ψ̇ + φ̇ cos θ the spin component; the slow root
    Ω = 2 m g l / (I3 ω3 + √(I3²ω3² − 4 I1 m g l cos θ)). Initial state: tilt θ about global x,
    global angular velocity ω = Ω e_z + (ω3 − Ω cos θ) k (k the symmetry axis), λ̇ = ½ Eᵀω."""

    g = 9.81

    def __init__(self, kind):
        self.kind = kind
        if kind == "point mass":
            self.m, self.l, self.Jt, self.Ja = 1.0, 0.5, 0.05, 0.08
            self.length = self.l
            self.I1, self.I3 = self.Jt + self.m * self.l**2, self.Ja
            self.mgl = self.m * self.g * self.l
            self.theta, self.w3 = math.radians(30.0), 40.0
        else:
            self.rho_a, self.rho_ip, self.rho_iy, self.length = 2.0, 0.05, 0.02, 0.6
            L = self.length
            self.I1, self.I3 = self.rho_a * L**3 / 3 + self.rho_iy * L, self.rho_ip * L
            self.mgl = self.rho_a * L * self.g * L / 2
            self.theta, self.w3 = math.radians(40.0), 60.0
        disc = (self.I3 * self.w3) ** 2 - 4 * self.I1 * self.mgl * math.cos(self.theta)
        self.Omega = 2 * self.mgl / (self.I3 * self.w3 + math.sqrt(disc))
        self.lam0 = np.array([math.cos(self.theta / 2), math.sin(self.theta / 2), 0.0, 0.0])

    def model(self, periods, n_out=400, eps=1e-12):
        k = R_(self.lam0) @ [0.0, 0.0, 1.0]
        omega = self.Omega * np.array([0.0, 0.0, 1.0]) + (self.w3 - self.Omega * math.cos(self.theta)) * k
        lamd = 0.5 * E_(self.lam0).T @ omega
        m = spacar.Model()
        m.beam(1, 1, 2, 3, 4, 1.0, 0.0, 0.0)
        m.x(3, 0.0, 0.0, self.length)  # reference: upright; the assembly tilts it with λ2
        m.fix(1)
        m.x(2, *self.lam0)
        m.x(4, *self.lam0)
        m.dynx(2)
        for i in range(4):
            m.xd(2, i + 1, lamd[i])
        if self.kind == "point mass":
            m.mass(3, self.m)
            m.mass(4, self.Jt, 0.0, 0.0, self.Jt, 0.0, self.Ja)
        else:
            m.emass(1, self.rho_a, self.rho_ip, self.rho_iy, self.rho_iy)
        m.gravity(0.0, 0.0, -self.g)
        m.timestep(n_out, periods * 2 * math.pi / self.Omega)
        return tighten(m, eps=eps)


@pytest.mark.parametrize("kind, periods", [("point mass", 4), ("uniform rod", 3)])
def test_heavy_symmetric_top_steady_precession(kind, periods):
    """Several precession periods at EPSINT = EPSIND = 1e-12 (point mass: spin 40 rad/s,
    θ = 30°, Ω = 1.794 rad/s, 14 s; rod: spin 60 rad/s, θ = 40°, Ω = 2.319 rad/s — neither is
    the gyroscopic approximation m g l/(I3 ω3)): θ stays constant to 1e-8 rad and the azimuth
    of the symmetry axis advances as Ω t to 1e-8 (relative to the total precession angle); the
    spin component ω′3, the energy ½ω′ᵀI_Oω′ + m g l cos θ and the angular momentum about the
    vertical through the pivot are conserved (formulation.md §10.2)."""
    top = Top(kind)
    assert top.Omega * (top.I3 * top.w3 - top.I1 * top.Omega * math.cos(top.theta)) == pytest.approx(
        top.mgl, rel=1e-14)
    assert top.Omega > 1.15 * top.mgl / (top.I3 * top.w3)
    res = spacar.simulate(top.model(periods))
    t = res.t
    k = res.node(3).x / top.length
    np.testing.assert_allclose(np.linalg.norm(k, axis=1), 1.0, rtol=0, atol=1e-12)
    theta = np.arccos(k[:, 2])
    assert np.abs(theta - top.theta).max() < 1e-8
    phi = np.unwrap(np.arctan2(k[:, 1], k[:, 0]))
    total = top.Omega * t[-1]
    assert total > periods * 2 * math.pi - 1e-9
    assert np.abs(phi - phi[0] - top.Omega * t).max() / total < 1e-8
    assert abs(np.polyfit(t, phi, 1)[0] / top.Omega - 1.0) < 1e-8
    # The rigid body: λ4 follows λ2 (rigid beam); spin, energy, vertical angular momentum.
    lam, lamd = res.node(2).x, res.node(2).xd
    np.testing.assert_allclose(np.abs(np.einsum("ti,ti->t", lam, res.node(4).x)), 1.0, rtol=0, atol=1e-12)
    w = body_angular_velocity(lam, lamd)
    assert np.abs(w[:, 2] - top.w3).max() < 1e-8 * top.w3
    I_O = np.diag([top.I1, top.I1, top.I3])
    energy = 0.5 * np.einsum("ti,ij,tj->t", w, I_O, w) + top.mgl * k[:, 2]
    assert np.abs(energy - energy[0]).max() / abs(energy[0]) < 1e-9
    Hz = np.array([(R_(lk) @ I_O @ wk)[2] for lk, wk in zip(lam, w)])
    assert np.abs(Hz - Hz[0]).max() / abs(Hz[0]) < 1e-9


def test_torsional_oscillator_on_a_skew_hinge():
    """A rigid body (full inertia tensor) on a HINGE with a skew axis a and torsional stiffness
    St (ESTIFF), hinge angle DYNE released from 0.3 rad: e1(t) = 0.3 cos(ωt) with
    ω² = St / (aᵀJ′a) (the hinge reactions take the other moments), to 1e-10 over 3 periods."""
    a = np.array([1.0, 2.0, 2.0]) / 3.0
    J = np.array([[2.0, 0.1, -0.2], [0.1, 3.0, 0.3], [-0.2, 0.3, 4.0]])
    stiffness = 5.0
    omega = math.sqrt(stiffness / (a @ J @ a))
    m = spacar.Model()
    m.hinge(1, 1, 2, *a)
    m.fix(1)
    m.dyne(1, 1)
    m.estiff(1, stiffness)
    m.mass(2, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
    m.e(1, 1, 0.3)
    m.timestep(200, 3 * 2 * math.pi / omega)
    res = spacar.simulate(tighten(m))
    np.testing.assert_allclose(res.deformation(1, 1), 0.3 * np.cos(omega * res.t), rtol=0, atol=1e-10)
    # the body turns about a only: R(λ) a = a
    np.testing.assert_allclose([R_(lk) @ a for lk in res.node(2).x], np.tile(a, (len(res.t), 1)), rtol=0, atol=1e-12)


def test_conical_pendulum():
    """A point mass on a rigid TRUSS from a fixed point, x and y DYNX (z calculable), gravity
    along −z, started on the steady cone of half-angle θ with Ω² = g/(L cos θ): it stays on the
    cone (z = −L cos θ) and its azimuth advances as Ω t, to 1e-10 over 3 revolutions."""
    L, g, th = 1.3, 9.81, math.radians(35.0)
    omega = math.sqrt(g / (L * math.cos(th)))
    m = spacar.Model()
    m.truss(1, 1, 2)
    m.fix(1)
    m.x(2, L * math.sin(th), 0.0, -L * math.cos(th))
    m.dynx(2, 1, 2)
    m.mass(2, 0.7)
    m.gravity(0.0, 0.0, -g)
    m.xd(2, 2, omega * L * math.sin(th))
    m.timestep(300, 3 * 2 * math.pi / omega)
    res = spacar.simulate(tighten(m))
    x = res.node(2).x
    np.testing.assert_allclose(x[:, 2], -L * math.cos(th), rtol=0, atol=1e-10)
    np.testing.assert_allclose(np.unwrap(np.arctan2(x[:, 1], x[:, 0])), omega * res.t, rtol=0, atol=1e-10)


# =============================================================================================
# BEAM cantilever: bending in both planes, torsion
# =============================================================================================

TABLE_10_3 = {  # formulation.md §10.3: ω_i for EI = ρA = L = 1, consistent mass
    1: ("3.532732", "34.80689"),
    2: ("3.517715", "22.22147", "75.15708"),
    4: ("3.516130", "22.06017", "62.17489"),
    8: ("3.516023", "22.03625", "61.73474"),
}
EXACT_BENDING = np.array([1.8751040687119611, 4.6940911329741745, 7.8547574382376126]) ** 2
EI_Y, EI_Z, GI_P, RHO_A, RHO_IP = 1.0, 4.0, 1.0, 1.0, 0.01


def matches_printed(value, printed):
    """|value − printed| within half a unit of the printed value's last digit (+ 1e-9 rel)."""
    decimals = len(printed.split(".")[1])
    return abs(value - float(printed)) <= 0.5 * 10.0**-decimals + 1e-9 * abs(value)


@pytest.fixture(scope="module")
def cantilever_modes():
    """Per mesh n: frequencies of the three decoupled groups of DOFs (torsion e2, bending about
    local y e3/e4, bending about local z e5/e6) from M̄ and the numerically linearized K."""
    out = {}
    for n in (1, 2, 4, 8, 16):
        Mbar, K, labels = linearize(cantilever(n, EIy=EI_Y, EIz=EI_Z, GIp=GI_P, rhoA=RHO_A, rhoIp=RHO_IP))
        groups = {"torsion": [2], "bending y": [3, 4], "bending z": [5, 6]}
        idx = {g: [j for j, (_, d) in enumerate(labels) if d in ds] for g, ds in groups.items()}
        freqs = {}
        for g, rows in idx.items():
            others = [j for j in range(len(labels)) if j not in rows]
            scaleM, scaleK = np.abs(Mbar).max(), np.abs(K).max()
            assert np.abs(Mbar[np.ix_(rows, others)]).max(initial=0.0) < 1e-12 * scaleM
            assert np.abs(K[np.ix_(rows, others)]).max(initial=0.0) < 1e-9 * scaleK
            Kg = K[np.ix_(rows, rows)]
            assert np.abs(Kg - Kg.T).max() < 1e-9 * np.abs(Kg).max()
            w2 = eigh(0.5 * (Kg + Kg.T), Mbar[np.ix_(rows, rows)], eigvals_only=True)
            assert w2.min() > 0.0
            freqs[g] = np.sqrt(np.sort(w2))
        out[n] = freqs
    return out


@pytest.mark.parametrize("n", [1, 2, 4, 8])
def test_cantilever_bending_frequencies_match_table_in_both_planes(cantilever_modes, n):
    """EIy = 1, EIz = 4, ρA = 1, L = 1, e1 rigid, torsion with rotary inertia only (EMASS e 1
    0.01 0 0): the bending modes about local y reproduce the table of formulation.md §10.3
    digit for digit, those about local z the same times √(EIz/ρA L⁴) = 2 (the planes separate).
    Torsion and the two bending planes are decoupled in M̄ and K."""
    wy = cantilever_modes[n]["bending y"]
    wz = cantilever_modes[n]["bending z"]
    for i, printed in enumerate(TABLE_10_3[n]):
        assert matches_printed(wy[i] / math.sqrt(EI_Y / RHO_A), printed), (i, wy[i], printed)
        assert matches_printed(wz[i] / math.sqrt(EI_Z / RHO_A), printed), (i, wz[i], printed)


def test_cantilever_bending_converges_to_the_analytic_frequencies(cantilever_modes):
    """β_i² √(EI/ρA L⁴) with β1 = 1.8751, β2 = 4.6941: from above, monotonically; the fourth
    power of h in the error of ω1 (cubic Hermite elements, consistent mass)."""
    for plane, EI in (("bending y", EI_Y), ("bending z", EI_Z)):
        scale = math.sqrt(EI / RHO_A)
        errors = []
        for n in (1, 2, 4, 8, 16):
            w = cantilever_modes[n][plane] / scale
            k = min(len(w), 2)
            assert np.all(w[:k] > EXACT_BENDING[:k])
            errors.append(w[0] / EXACT_BENDING[0] - 1.0)
        assert np.all(np.diff(errors) < 0)
        assert errors[-1] < 2e-7
        order = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
        assert all(3.8 < p < 4.2 for p in order[1:]), order


def test_cantilever_torsion_converges_from_above_at_second_order(cantilever_modes):
    """Torsion (GIp = 1, ρIp = 0.01, L = 1): exact ω_k = (2k−1)π/2 · √(GIp/(ρIp L²)). Linear
    interpolation of the section angular velocity with consistent mass gives exactly the discrete
    dispersion relation of linear elements, ω_h² = (6c²/h²)(1 − cos κh)/(2 + cos κh) with
    κ = (2k−1)π/(2L), c² = GIp/ρIp; hence convergence from above with
    ω_h/ω − 1 ≈ (κh)²/24: rate 2 (log2 of successive error ratios)."""
    c = math.sqrt(GI_P / RHO_IP)
    errors = {1: [], 2: []}
    for n in (1, 2, 4, 8, 16):
        w = cantilever_modes[n]["torsion"]
        assert len(w) == n
        h = 1.0 / n
        for k in range(1, n + 1):
            kappa = (2 * k - 1) * math.pi / 2
            discrete = math.sqrt(6 * c**2 / h**2 * (1 - math.cos(kappa * h)) / (2 + math.cos(kappa * h)))
            assert w[k - 1] == pytest.approx(discrete, rel=1e-9)
            exact = kappa * c
            assert w[k - 1] > exact
            if k in errors:
                errors[k].append((n, w[k - 1] / exact - 1.0))
    for k, series in errors.items():
        e = [err for _, err in series]
        rates = np.log2(np.array(e[:-1]) / np.array(e[1:]))
        assert np.all(np.diff(e) < 0)
        assert abs(rates[-1] - 2.0) < 0.05, (k, series, rates)
    assert errors[1][-1][1] < 1e-3  # n = 16: 0.04 % above the exact 15.70796


@pytest.mark.parametrize("n", [1, 4, 8])
def test_cantilever_numerical_linearization_agrees_with_linearize(n):
    """The finite-difference K = −M̄ ∂q̈/∂q and M̄ used above equal M0 and K0 + N0 + G0 of
    spacar.linearize (formulation.md §7) in the straight, unloaded state (N0 = G0 = 0)."""
    Mbar, K, labels = linearize(cantilever(n, EIy=EI_Y, EIz=EI_Z, GIp=GI_P, rhoA=RHO_A, rhoIp=RHO_IP))
    lin = spacar.linearize(cantilever(n, EIy=EI_Y, EIz=EI_Z, GIp=GI_P, rhoA=RHO_A, rhoIp=RHO_IP))
    assert [lbl[1:] for lbl in lin.z_labels] == labels
    np.testing.assert_allclose(lin.M0, Mbar, rtol=0, atol=1e-14 * np.abs(Mbar).max())
    np.testing.assert_allclose(lin.stiffness, K, rtol=0, atol=1e-10 * np.abs(K).max())
    np.testing.assert_allclose(lin.K0, K, rtol=0, atol=1e-10 * np.abs(K).max())


# =============================================================================================
# Spatial closed loops: RSSR (truss coupler, spherical joints) and RSUR (beam coupler, spherical
# joint at the crank, universal joint of two hinges at the rocker)
# =============================================================================================

@pytest.mark.parametrize("coupler", ["truss", "beam"], ids=["RSSR", "RSUR"])
def test_driven_spatial_four_bar_matches_closed_form(coupler):
    """Skew crank and rocker axes (z and (1, 0.2, 0.1)), crank driven by INPUTE on its hinge at
    1.5 rad/s for 10 s (2.4 turns, kinematic analysis at 201 output times, EPSKIN = 1e-12): the
    rocker hinge angle equals the closed-form solution of the loop equation to 1e-10; every
    LAMBDA node keeps unit length, the loop stays closed and the rigid deformations vanish,
    all to EPSKIN."""
    epskin = 1e-12
    model = rssr_model(coupler)
    model.epskin(epskin)
    res = spacar.simulate(model)
    theta = res.deformation(5, 1)
    np.testing.assert_allclose(theta, 1.5 * res.t, rtol=0, atol=1e-12)
    phi = RSSR.rocker_angle(theta)
    np.testing.assert_allclose(res.deformation(6, 1), phi, rtol=0, atol=1e-10)
    assert np.ptp(phi) > 0.8  # the rocker swings through 0.89 rad
    check_closed_loop(model, res, epskin, n_lambda=5 if coupler == "truss" else 8)
    np.testing.assert_allclose(res.node(2).x, np.array([RSSR.B(t) for t in theta]), rtol=0, atol=1e-12)


def check_closed_loop(model, res, epskin, n_lambda):
    """|λ|² − 1 of every LAMBDA node, the coupler length |C − B| and every fixed deformation
    (beams, hinge misalignments, truss, L2MIN1) within EPSKIN at all output times."""
    lam = lambda_nodes(model)
    assert len(lam) == n_lambda
    for n in lam:
        assert np.abs((res.node(n).x ** 2).sum(axis=1) - 1.0).max() <= epskin, n
    closure = np.linalg.norm(res.node(3).x - res.node(2).x, axis=1) - RSSR.Lc
    assert np.abs(closure).max() <= epskin
    for e, el in model.elements.items():
        fixed = [i for i, c in enumerate(el.cls) if c.name.lower() == "fixed"]
        assert np.abs(res.element(e).e[:, fixed]).max(initial=0.0) <= epskin, e


def four_bar_energy(initial, res):
    """T = ½ ẋᵀ M ẋ from the engine's mass matrix at each output state (Simulation.evaluate on
    a copy of the model taken before the run); V of gravity for the rigid straight beams and
    truss (½ρA l0 g at each end node, exact when t_p = t_q) and the point mass at C."""
    model = initial.copy()
    sim = assembled(model)
    T = np.empty(len(res.t))
    for k, t in enumerate(res.t):
        sim.evaluate(t, res.element(5).e[k, :1], res.element(5).ed[k, :1])
        xd = np.array(sim.data.xd)
        T[k] = 0.5 * xd @ np.array(sim.data.M) @ xd
        np.testing.assert_allclose(np.array(sim.data.x), res.x[k], rtol=0, atol=1e-9)
    g = np.array([0.0, 0.0, -9.81])
    x = {n: res.node(n).x for n in (1, 2, 3, 4)}
    lengths = {1: RSSR.r1, 2: RSSR.r3, 3: RSSR.Lc}
    ends = {1: (1, 2), 2: (4, 3), 3: (2, 3)}
    V = -0.2 * x[3] @ g
    for e, (p, q) in ends.items():
        V -= model.elements[e].emass[0] * lengths[e] * (0.5 * (x[p] + x[q])) @ g
    return T + V


@pytest.mark.parametrize("coupler", ["truss", "beam"], ids=["RSSR", "RSUR"])
def test_free_spatial_four_bar_under_gravity_for_10_s(coupler):
    """One DOF (the crank hinge angle, DYNE) with distributed masses, a point mass, a rigid
    body on the coupler (RSUR) and gravity, started at 6 rad/s: the crank makes ~13 turns in
    10 s (EPSINT = EPSIND = 1e-10, EPSKIN = 1e-10). At all 501 output times every LAMBDA node
    has |λ|² − 1 ≤ EPSKIN, the loop is closed and every rigid deformation (beams, hinge
    misalignments, truss) is ≤ EPSKIN; T + V is conserved to 1e-8 (relative)."""
    epskin = 1e-10
    model = rssr_model(coupler, dynamic=True, rate=6.0, n_out=500)
    tighten(model, eps=1e-10, epskin=epskin)
    initial = model.copy()
    res = spacar.simulate(model)
    assert res.t[-1] == 10.0 and len(res.t) == 501
    assert res.deformation(5, 1)[-1] > 12 * 2 * math.pi
    check_closed_loop(model, res, epskin, n_lambda=5 if coupler == "truss" else 8)
    energy = four_bar_energy(initial, res)
    assert np.abs(energy - energy[0]).max() / abs(energy[0]) < 1e-8
