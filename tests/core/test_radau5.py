"""Tests of the Radau IIA integrator (order 5, Hairer's RADAU5 step control) through the test binding
`spacar._testing.radau5_solve`: order on a problem with an exact solution, dense output, stiff
reference problems against scipy's Radau at tight tolerance, and step counts independent of the
stiffness."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from spacar import _testing

OSCILLATOR = np.array([[0.0, 1.0], [-1.0, 0.0]])


def oscillator_exact(t):
    t = np.asarray(t, dtype=float)
    return np.stack([np.cos(t), -np.sin(t)], axis=-1)


def solve_linear(A, y0, t_end, touts, rtol, atol, **kw):
    return _testing.radau5_solve(lambda t, y: A @ y, lambda t, y: A, 0.0, np.asarray(y0, float), t_end,
                              list(touts), rtol, atol, **kw)


def test_order_five_with_fixed_steps():
    # Loose tolerances: the steps are set by hmax (h = hmax from the start, t_end a multiple of it),
    # so the global error shows the order of the method: 5.
    errors = []
    for n in (10, 20, 40):
        h = 4.0 / n
        r = solve_linear(OSCILLATOR, [1.0, 0.0], 4.0, [4.0], 1.0, 1.0, hmax=h, first_step=h)
        # (possibly one tiny last step left by the rounding of t)
        assert r["naccept"] in (n, n + 1) and r["nreject"] == 0
        errors.append(np.abs(r["y"][-1] - oscillator_exact(4.0)).max())
    orders = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert all(4.7 < p < 5.4 for p in orders), orders


def test_dense_output_between_steps():
    # Output times inside long steps come from the collocation polynomial (order 3 in h): with a
    # tight tolerance they agree with the exact solution to about the tolerance.
    touts = np.linspace(0.0, 10.0, 1001)
    r = solve_linear(OSCILLATOR, [1.0, 0.0], 10.0, touts, 1e-9, 1e-9)
    assert r["naccept"] < 200  # several outputs per step
    assert np.abs(r["y"] - oscillator_exact(touts)).max() < 1e-7


def test_tolerance_controls_the_global_error():
    touts = np.linspace(0.0, 10.0, 11)
    for tol in (1e-4, 1e-6, 1e-8, 1e-10):
        r = solve_linear(OSCILLATOR, [1.0, 0.0], 10.0, touts, tol, tol)
        err = np.abs(r["y"] - oscillator_exact(touts)).max()
        assert err < 100 * tol, (tol, err)


def test_step_count_does_not_grow_with_stiffness():
    # Eigenvalues -1 and -lambda: an explicit method needs ~lambda steps; Radau IIA is L-stable, so
    # after the initial layer the steps follow the slow component only.
    steps = {}
    for lam in (1e2, 1e4, 1e6):
        A = np.array([[-1.0, 0.0], [1.0, -lam]])
        touts = [0.0, 1.0, 5.0, 10.0]
        r = solve_linear(A, [1.0, 1.0], 10.0, touts, 1e-6, 1e-9)
        slow = np.exp(-np.array(touts))
        assert np.abs(r["y"][1:, 0] - slow[1:]).max() < 1e-5
        steps[lam] = r["nsteps"]
        assert r["njev"] == 1  # linear: the Jacobian is never stale
    assert steps[1e6] <= 1.3 * steps[1e2], steps
    assert steps[1e6] < 200, steps


def van_der_pol(eps):
    def f(t, y):
        return np.array([y[1], ((1.0 - y[0] ** 2) * y[1] - y[0]) / eps])

    def jac(t, y):
        return np.array([[0.0, 1.0], [(-2.0 * y[0] * y[1] - 1.0) / eps, (1.0 - y[0] ** 2) / eps]])

    return f, jac


def test_van_der_pol_mu_1e3_against_scipy():
    # y'' - mu (1 - y^2) y' + y = 0 with mu = 1000 in Hairer's scaled time (eps = 1/mu^2), two
    # periods of relaxation oscillations with their steep jumps.
    f, jac = van_der_pol(1e-6)
    y0 = [2.0, -0.66]
    touts = np.linspace(0.0, 2.0, 11)
    ref = solve_ivp(f, (0.0, 2.0), y0, method="Radau", rtol=1e-10, atol=1e-10, jac=jac, t_eval=touts)
    assert ref.success
    for tol, bound in ((1e-6, 3e-5), (1e-8, 3e-7)):
        r = _testing.radau5_solve(f, jac, 0.0, np.array(y0), 2.0, list(touts), tol, tol)
        err = (np.abs(r["y"] - ref.y.T) / (1.0 + np.abs(ref.y.T))).max()
        assert err < bound, (tol, err)
        # Hairer & Wanner report about 500 steps at tol 1e-6 for this problem.
        assert r["nsteps"] < (700 if tol == 1e-6 else 1500), r
        assert r["njev"] < r["naccept"]  # Jacobians reused across steps
        assert r["ndec"] < r["nsteps"]


def robertson(t, y):
    return np.array([-0.04 * y[0] + 1e4 * y[1] * y[2],
                     0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] ** 2,
                     3e7 * y[1] ** 2])


def robertson_jac(t, y):
    return np.array([[-0.04, 1e4 * y[2], 1e4 * y[1]],
                     [0.04, -1e4 * y[2] - 6e7 * y[1], -1e4 * y[1]],
                     [0.0, 6e7 * y[1], 0.0]])


def test_robertson_against_scipy():
    touts = [0.0, 1e-2, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5]
    ref = solve_ivp(robertson, (0.0, 1e5), [1.0, 0.0, 0.0], method="Radau", rtol=1e-10, atol=1e-14,
                    jac=robertson_jac, t_eval=touts)
    assert ref.success
    for tol in (1e-6, 1e-8):
        r = _testing.radau5_solve(robertson, robertson_jac, 0.0, np.array([1.0, 0.0, 0.0]), 1e5, touts,
                               tol, 1e-4 * tol)
        rel = np.abs(r["y"][1:] - ref.y.T[1:]) / np.abs(ref.y.T[1:])
        assert rel.max() < 20 * tol, (tol, rel.max())
        assert abs(r["y"][-1].sum() - 1.0) < 1e-10  # the method conserves linear invariants
        assert r["nsteps"] < 300


def test_bad_arguments():
    with pytest.raises(ValueError):
        solve_linear(OSCILLATOR, [1.0, 0.0], 1.0, [2.0], 1e-6, 1e-6)
    with pytest.raises(ValueError):
        solve_linear(OSCILLATOR, [1.0, 0.0], 1.0, [1.0], -1.0, 1e-6)
