"""Every integration method through the one stepper interface (issue 35): the stepper a run makes
(stepper.hpp's method table, `_core.solve_ode`) on problems with exact solutions, its
outputs, counters and guards. A new method in the table is checked here without a line of its own.
"""
import math

import numpy as np
import pytest

from spacar import _core
from spacar.errors import IntegrationError, InputError

STEPPERS = [m for m in _core.integration_methods if m != "auto"]
OMEGA = 3.0


def oscillator(t, y):
    """q̈ = −ω² q as (q, q̇): positions first, rates last."""
    return np.array([y[1], -OMEGA**2 * y[0]])


def oscillator_jacobian(t, y):
    return np.array([[0.0, 1.0], [-OMEGA**2, 0.0]])


def exact(t):
    return np.array([math.cos(OMEGA * t), -OMEGA * math.sin(OMEGA * t)])


def solve(method, f=oscillator, jac=oscillator_jacobian, t_end=2.0, touts=(0.0, 0.5, 1.3, 2.0), rtol=1e-8,
          atol=1e-10, **kw):
    return _core.solve_ode(method, f, jac, 0.0, np.array([1.0, 0.0]), t_end, list(touts), rtol, atol,
                                  positions=1, **kw)


def test_the_method_table():
    assert _core.integration_methods[0] == "auto"
    assert set(_core.implicit_methods) <= set(STEPPERS)
    assert {"dop853", "dopri5"}.isdisjoint(_core.implicit_methods)


@pytest.mark.parametrize("method", STEPPERS)
def test_accuracy_and_outputs(method):
    """The oscillator to its tolerance at every output time, t0 and t_end exactly."""
    r = solve(method)
    assert r["t"] == [0.0, 0.5, 1.3, 2.0] and r["t_reached"] == 2.0
    np.testing.assert_array_equal(r["y"][0], [1.0, 0.0])
    np.testing.assert_array_equal(r["y"][-1], r["y_end"])
    # generalized-α is of order 2: its global error follows the tolerance only roughly
    bound = 1e-4 if method == "generalized_alpha" else 1e-6
    for t, y in zip(r["t"], r["y"]):
        np.testing.assert_allclose(y, exact(t), atol=bound * OMEGA)
    assert r["nsteps"] == r["naccept"] + r["nreject"] and r["naccept"] > 0
    assert r["last_step"] > 0
    if method in _core.implicit_methods:
        assert r["njev"] >= 1 and r["ndec"] >= 1
    else:
        assert r["njev"] == r["ndec"] == r["nnewton"] == 0


@pytest.mark.parametrize("method", STEPPERS)
def test_tighter_tolerance_smaller_error(method):
    loose, tight = (abs(solve(method, rtol=eps, atol=1e-3 * eps)["y_end"] - exact(2.0)).max() for eps in (1e-4, 1e-8))
    assert tight < loose


@pytest.mark.parametrize("method", STEPPERS)
def test_step_limit(method):
    with pytest.raises(IntegrationError, match="more than 3 steps at t = "):
        solve(method, max_steps=3)


@pytest.mark.parametrize("method", STEPPERS)
def test_cannot_start_on_a_non_finite_rhs(method):
    with pytest.raises(IntegrationError, match="cannot start, rhs failed at the initial state"):
        solve(method, f=lambda t, y: np.array([np.nan, 0.0]))


@pytest.mark.parametrize("method", STEPPERS)
def test_maximum_step_and_first_step(method):
    r = solve(method, hmax=0.01, first_step=0.005, rtol=1e-3, atol=1e-6)
    assert r["naccept"] >= 200  # 2 s in steps of at most 0.01 s


@pytest.mark.parametrize("method", list(_core.implicit_methods))
def test_implicit_methods_need_a_jacobian(method):
    with pytest.raises(ValueError, match="no Jacobian callback set"):
        solve(method, jac=None)


def test_auto_is_a_choice_of_steppers():
    with pytest.raises(ValueError, match="auto is a choice of steppers"):
        solve("auto")
    with pytest.raises(InputError, match="unknown integration method 'rk4'"):
        solve("rk4")
