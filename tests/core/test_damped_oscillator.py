"""Correctness against an independent reference: the damped oscillator in closed form.

A point mass m on a PLTRUSS spring from a fixed node, its elongation e the one degree of freedom
(DYNE; the mass's coordinate follows as x = l0 + e), released at rest from e = x0. The truss
law σ = EA e/l0 + EDAMPP ė/l0 (formulation §4) and the exact elongation of a truss along its axis
make m ë + c ė + k e = 0 with k = EA/l0 and c = EDAMPP/l0: a linear oscillator whose motion is
known in closed form, under-, over- and (at ω = 10⁴ rad/s) stiffly damped."""

import numpy as np
import pytest

import spacar

MASS, L0, X0 = 2.0, 0.5, 1e-2
METHODS = ("radau5", "auto", "dop853")


def oscillator(omega, zeta, t_end, n_out, eps):
    """The truss oscillator with natural frequency omega [rad/s] and damping ratio zeta."""
    k, c = MASS * omega**2, 2.0 * zeta * MASS * omega
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(1, 0.0, 0.0)
    m.x(2, L0, 0.0)  # the reference length l0 from the initial positions ...
    m.fix(1)
    m.fix(2, 2)
    m.dyne(1, 1)
    m.e(1, 1, X0)  # ... and the initial elongation on top of it
    m.mass(2, MASS)
    m.estiff(1, k * L0)
    m.edampp(1, c * L0)
    m.timestep(n_out, t_end)
    m.epsint(eps)
    m.epsind(eps)
    return m


def closed_form(t, omega, zeta):
    """e(t), ė(t) from e(0) = X0, ė(0) = 0. Overdamped, ωd is imaginary and cos, sin/ωd become
    cosh, sinh/|ωd|: one formula for both."""
    wd = omega * np.sqrt(complex(1.0 - zeta**2))
    decay = np.exp(-zeta * omega * t)
    e = decay * X0 * (np.cos(wd * t) + zeta * omega / wd * np.sin(wd * t))
    ed = -decay * X0 * omega**2 / wd * np.sin(wd * t)
    return e.real, ed.real


def check_against_closed_form(res, omega, zeta, tol):
    e, ed = closed_form(res.t, omega, zeta)
    k, c = MASS * omega**2, 2.0 * zeta * MASS * omega
    assert np.abs(res.deformation(1, 1) - e).max() < tol * X0
    assert np.abs(res.node(2).x[:, 0] - (L0 + e)).max() < tol * X0
    assert np.abs(res.deformation(1, 1, "ed") - ed).max() < tol * omega * X0
    # The stress: the constitutive law at the recorded state, and the closed form's.
    assert np.allclose(res.stress(1, 1), k * res.deformation(1, 1) + c * res.deformation(1, 1, "ed"),
                       rtol=1e-12, atol=1e-12 * k * X0)
    assert np.abs(res.stress(1, 1) - (k * e + c * ed)).max() < tol * (k + c * omega) * X0


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("zeta", [0.1, 2.0], ids=["underdamped", "overdamped"])
def test_motion_and_stress_follow_the_closed_form(method, zeta):
    # 1 Hz over three periods at EPSINT = EPSIND = 1e-8: the largest errors measured are 7e-8 of
    # X0 in e and 2.3e-7 of ω·X0 in ė (DOP853, overdamped); 1e-6 asked.
    omega = 2.0 * np.pi
    res = spacar.simulate(oscillator(omega, zeta, t_end=3.0, n_out=30, eps=1e-8), method=method, progress=False)
    assert res.t[-1] == pytest.approx(3.0)
    check_against_closed_form(res, omega, zeta, tol=1e-6)


# At EPSINT <= 3e-8 auto stays on DOP853 here (3904 steps, 1615 rejected): the decayed state lies
# below the absolute tolerance and DOP853 alternates steps of h|λ| 20-80 with rejections, but its
# stiffness test (Hairer's: 15 steps with h|λ| above 6.1 before 6 in a row below it) sees h|λ| of
# 1.5-5 at most accepted steps and rarely counts more than a few in a row (measured 2026-11-24; the
# 1000-steps-ahead guard would allow the switch at the pace of these steps). Found by this test;
# the xfail goes when the detection sees this kind of stiffness.
@pytest.mark.parametrize("eps", [1e-6, pytest.param(1e-8, marks=pytest.mark.xfail(
    strict=True, reason="auto stays on DOP853 at EPSINT 1e-8 (the stiffness test rarely fires)"))])
def test_stiff_oscillator_takes_few_implicit_steps(eps):
    # ω = 10⁴ rad/s, ζ = 0.5 over 1 s: the motion has decayed after a few ms, after which DOP853's
    # steps are held at its stability limit h|λ| ≈ 6 (about 2000 steps at 1e-6); Radau's grow.
    omega, zeta = 1e4, 0.5
    runs = {method: spacar.simulate(oscillator(omega, zeta, t_end=1.0, n_out=10, eps=eps), method=method,
                                    progress=False) for method in METHODS}
    for res in runs.values():
        check_against_closed_form(res, omega, zeta, tol=100 * eps)
    steps = {method: res.stats["steps"] for method, res in runs.items()}
    assert steps["dop853"] > 1000, steps
    assert 5 * steps["radau5"] < steps["dop853"], steps
    assert 5 * steps["auto"] < steps["dop853"], steps
    assert runs["auto"].stats["method"].startswith("auto: dop853→radau5"), runs["auto"].stats
