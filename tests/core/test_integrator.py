"""Tests of the embedded Runge-Kutta integrators (DOP853, DOPRI5) through the test binding
`spacar._testing.explicit_rk_solve`, against exact solutions and the known orders of the methods."""

import math

import numpy as np
import pytest

from spacar import _testing

METHODS = ["dop853", "dopri5"]
# Order of the solution and of the dense output of each method.
ORDER = {"dop853": 8, "dopri5": 5}
DENSE_ORDER = {"dop853": 7, "dopri5": 4}


def oscillator(t, y):
    return np.array([y[1], -y[0]])


def oscillator_exact(t):
    t = np.asarray(t, dtype=float)
    return np.stack([np.cos(t), -np.sin(t)], axis=-1)


Y0_OSCILLATOR = np.array([1.0, 0.0])

# Restricted three-body problem (Hairer, Norsett & Wanner, Sec. II.0): a periodic orbit.
ARENSTORF_MU = 0.012277471
ARENSTORF_PERIOD = 17.0652165601579625588917206249
ARENSTORF_Y0 = np.array([0.994, 0.0, 0.0, -2.00158510637908252240537862224])


def arenstorf(t, y):
    mu, mp = ARENSTORF_MU, 1.0 - ARENSTORF_MU
    x1, x2, v1, v2 = y
    d1 = ((x1 + mu) ** 2 + x2**2) ** 1.5
    d2 = ((x1 - mp) ** 2 + x2**2) ** 1.5
    return np.array(
        [
            v1,
            v2,
            x1 + 2 * v2 - mp * (x1 + mu) / d1 - mu * (x1 - mp) / d2,
            x2 - 2 * v1 - mp * x2 / d1 - mu * x2 / d2,
        ]
    )


def solve_with_fixed_step(method, t_end, steps, touts, f=oscillator, y0=Y0_OSCILLATOR):
    """A huge tolerance never rejects, so hmax alone sets the step (up to the automatic first step,
    which can only be smaller)."""
    return _testing.explicit_rk_solve(f, 0.0, y0, t_end, touts, 1e3, 1e3, method=method,
                                      hmax=t_end / steps * (1 + 1e-9))


@pytest.mark.parametrize("method", METHODS)
def test_harmonic_oscillator_is_accurate_at_tight_tolerance(method):
    t_end = 10.0
    r = _testing.explicit_rk_solve(oscillator, 0.0, Y0_OSCILLATOR, t_end, [t_end], 1e-11, 1e-12,
                                   method=method)
    assert np.abs(r["y"][-1] - oscillator_exact(t_end)).max() < 1e-9
    assert r["naccept"] > 0 and r["nfev"] > r["naccept"]


def test_arenstorf_orbit_closes_after_one_period():
    r = _testing.explicit_rk_solve(arenstorf, 0.0, ARENSTORF_Y0, ARENSTORF_PERIOD, [ARENSTORF_PERIOD],
                                   1e-10, 1e-10)
    assert np.abs(r["y"][-1] - ARENSTORF_Y0).max() < 1e-5
    # Hairer's DOP853 (and scipy's) needs about 2.8e3 evaluations here; guard the efficiency.
    assert r["nfev"] < 3200


@pytest.mark.parametrize("method", METHODS)
def test_dense_output_at_intermediate_times_matches_exact_solution(method):
    t_end = 10.0
    touts = np.sort(np.random.default_rng(1).uniform(0.0, t_end, 50))
    r = _testing.explicit_rk_solve(oscillator, 0.0, Y0_OSCILLATOR, t_end, touts, 1e-11, 1e-12,
                                   method=method)
    np.testing.assert_array_equal(r["t"], touts)
    assert r["y"].shape == (50, 2)
    assert np.abs(r["y"] - oscillator_exact(touts)).max() < 1e-8


@pytest.mark.parametrize("method", METHODS)
def test_global_error_converges_with_the_order_of_the_method(method):
    t_end = 10.0
    steps = {"dop853": 20, "dopri5": 100}[method]
    errors = []
    for n in (steps, 2 * steps):
        r = solve_with_fixed_step(method, t_end, n, [t_end])
        errors.append(np.abs(r["y"][-1] - oscillator_exact(t_end)).max())
    assert math.log2(errors[0] / errors[1]) == pytest.approx(ORDER[method], abs=0.5)


@pytest.mark.parametrize("method", METHODS)
def test_dense_output_within_one_step_has_the_dense_order(method):
    # One step of size h: the interpolation error inside the step is O(h^(dense order + 1)).
    errors = []
    for h in (0.2, 0.1):
        touts = np.linspace(0.0, h, 11)[1:-1]
        r = solve_with_fixed_step(method, h, 1, touts)
        assert r["naccept"] == 1
        errors.append(np.abs(r["y"] - oscillator_exact(touts)).max())
    assert math.log2(errors[0] / errors[1]) == pytest.approx(DENSE_ORDER[method] + 1, abs=0.5)


@pytest.mark.parametrize("method", METHODS)
def test_end_points_are_exact_and_dense_requests_do_not_change_the_solution(method):
    t_end = 7.0
    touts = [0.0, 0.0, 1.234, 5.0, t_end, t_end]
    r = _testing.explicit_rk_solve(oscillator, 0.0, Y0_OSCILLATOR, t_end, touts, 1e-8, 1e-8,
                                   method=method)
    np.testing.assert_array_equal(r["y"][0], Y0_OSCILLATOR)
    np.testing.assert_array_equal(r["y"][1], Y0_OSCILLATOR)
    np.testing.assert_array_equal(r["y"][4], r["y"][5])
    only_end = _testing.explicit_rk_solve(oscillator, 0.0, Y0_OSCILLATOR, t_end, [t_end], 1e-8, 1e-8,
                                          method=method)
    np.testing.assert_array_equal(r["y"][-1], only_end["y"][-1])
    assert r["naccept"] == only_end["naccept"]


@pytest.mark.parametrize("method", METHODS)
def test_max_step_is_respected(method):
    r = _testing.explicit_rk_solve(oscillator, 0.0, Y0_OSCILLATOR, 1.0, [1.0], 1e-3, 1e-3,
                                   method=method, hmax=0.01)
    assert r["naccept"] >= 100


@pytest.mark.parametrize("method", METHODS)
def test_rhs_returning_nan_ends_in_an_error(method):
    def poisoned(t, y):
        return np.array([np.nan if t > 0.5 else 1.0])

    with pytest.raises(Exception) as info:
        _testing.explicit_rk_solve(poisoned, 0.0, np.array([0.0]), 2.0, [2.0], 1e-6, 1e-6, method=method)
    message = str(info.value)
    assert "step" in message or "non-finite" in message


def test_exception_in_python_rhs_propagates():
    def failing(t, y):
        raise ZeroDivisionError("rhs failed")

    with pytest.raises(ZeroDivisionError):
        _testing.explicit_rk_solve(failing, 0.0, np.array([1.0]), 1.0, [1.0], 1e-6, 1e-6)


def test_unknown_method_is_rejected():
    with pytest.raises(ValueError):
        _testing.explicit_rk_solve(oscillator, 0.0, Y0_OSCILLATOR, 1.0, [1.0], 1e-6, 1e-6, method="rk4")
