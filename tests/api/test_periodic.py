"""Periodic steady states and Floquet multipliers (issue 40): a pendulum on a vertically driven
support obeys Mathieu's equation θ'' + (δ − ε cos τ) θ = 0 about its rest state (δ = g/Lω²,
ε = a/L, τ = ωt); the boundaries of its instability tongues are Mathieu's characteristic values
(scipy.special.mathieu_a, mathieu_b: y'' + (a − 2q cos 2x) y = 0 with a = 4δ, q = 2ε), where a
Floquet multiplier reaches −1 (the first tongue, about δ = 1/4) or +1 (the second, about δ = 1).
The flexible slider-crank of the manual driven at constant crank speed has a periodic orbit that
shooting finds without a transient; with damping in the rod it is the state a long run settles to."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.special import mathieu_a, mathieu_b

import spacar
from spacar import floquet, periodic_orbit

L, G = 1.0, 9.81
EPS = 0.1   # support amplitude a / L


def pendulum():
    """A rigid pendulum of length L hanging from node 1, whose vertical position is an input."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(1, 0.0, 0.0)
    m.x(3, 0.0, -L)
    m.fix(1, 1)
    m.inputx(1, 2)
    m.dynx(2, 1)
    m.mass(3, 1.0)
    m.gravity(0.0, -G)
    return m


def support_motion(delta):
    """(period, inputs) of the support moving as a cos ωt, ω from δ = g / (L ω²)."""
    omega = np.sqrt(G / (L * delta))
    period = 2 * np.pi / omega
    ts = np.linspace(0.0, period, 4001)
    return period, {(1, 2): spacar.Table(ts, EPS * L * np.cos(omega * ts))}


def trace(delta):
    period, inputs = support_motion(delta)
    return float(np.trace(floquet(pendulum(), period, inputs=inputs, steps=1).monodromy))


def boundary(guess, sign):
    """δ where the monodromy's trace is 2·sign, by the secant method from around the guess."""
    a, b = guess * (1 - 1e-3), guess * (1 + 1e-3)
    fa, fb = trace(a) - 2 * sign, trace(b) - 2 * sign
    for _ in range(10):
        c = b - fb * (b - a) / (fb - fa)
        a, fa, b, fb = b, fb, c, trace(c) - 2 * sign
        if abs(b - a) < 1e-12 * b:
            break
    return b


@pytest.mark.parametrize("order, sign", [(1, -1), (2, +1)])
def test_the_boundaries_of_the_mathieu_tongues(order, sign):
    q = 2 * EPS
    for reference in (mathieu_b(order, q) / 4, mathieu_a(order, q) / 4):
        assert boundary(reference, sign) == pytest.approx(reference, rel=1e-6)


def test_inside_the_first_tongue_the_rest_state_is_unstable_outside_it_is_stable():
    period, inputs = support_motion(0.25)          # the middle of the first tongue
    inside = floquet(pendulum(), period, inputs=inputs)
    assert not inside.is_stable()
    assert inside.spectral_radius > 1.1
    assert np.all(inside.multipliers.real < 0)     # the period-doubling tongue: real, negative
    assert inside.residual < 1e-14                 # the rest state is periodic
    period, inputs = support_motion(0.5)
    outside = floquet(pendulum(), period, inputs=inputs)
    assert outside.is_stable()
    # Without damping the flow keeps areas (Liouville): the multipliers lie on the unit circle.
    assert np.abs(outside.multipliers) == pytest.approx([1.0, 1.0], abs=1e-7)
    for orbit in (inside, outside):
        assert np.linalg.det(orbit.monodromy) == pytest.approx(1.0, abs=1e-7)
        assert orbit.exponents.real.sum() == pytest.approx(0.0, abs=1e-6)
    assert outside.results.t[-1] == pytest.approx(period)
    assert outside.dof_labels == ["x(2,1)"]


def flexible_slider_crank(damping):
    m = spacar.read("examples/slidercrank.dat")    # the manual's: crank 1.5 rad/s, the rod's bending DYNE
    for e in (2, 3):
        m.edampp(e, 0.0, damping)
    return m


def test_the_damped_slider_crank_settles_to_the_orbit_shooting_finds():
    period = 2 * np.pi / 1.5
    orbit = periodic_orbit(flexible_slider_crank(1e-5), period)
    assert orbit.residual < 1e-10
    assert orbit.is_stable() and orbit.spectral_radius < 0.5
    assert orbit.iterations <= 3
    # The transient of a run from the manual's initial state dies out in 25 turns of the crank.
    long_run = flexible_slider_crank(1e-5)
    long_run.timestep(1, 25 * period)
    long_run.epsint(1e-10)
    long_run.epsind(1e-10)
    res = spacar.simulate(long_run, progress=False)
    assert res.q[-1] == pytest.approx(orbit.q, abs=1e-6 * np.abs(orbit.q).max())
    assert res.qd[-1] == pytest.approx(orbit.qd, abs=1e-6 * np.abs(orbit.qd).max())
    # The orbit's one-period run ends where it started.
    assert orbit.results.q[-1] == pytest.approx(orbit.q, abs=1e-10)
    assert orbit.results.qd[-1] == pytest.approx(orbit.qd, abs=1e-10)


def test_bad_input_is_refused_by_name():
    period, inputs = support_motion(0.5)
    with pytest.raises(spacar.InputError, match="period"):
        floquet(pendulum(), -1.0)
    with pytest.raises(spacar.InputError, match="qd must be 1 finite"):
        floquet(pendulum(), period, qd=[0.0, 1.0])
    with pytest.raises(spacar.InputError, match="max_iterations"):
        periodic_orbit(pendulum(), period, max_iterations=0)
    no_dofs = spacar.Model()
    no_dofs.plbeam(1, 1, 2, 3, 4)
    no_dofs.fix(1)
    no_dofs.inputx(2, 1)
    no_dofs.x(3, 1.0, 0.0)
    with pytest.raises(spacar.InputError, match="no degrees of freedom"):
        floquet(no_dofs, 1.0)
    with pytest.raises(spacar.TimeLimitError):
        periodic_orbit(flexible_slider_crank(1e-5), 2 * np.pi / 1.5, time_limit=0.05)



def test_a_table_that_does_not_cover_the_period_is_refused():
    period, inputs = support_motion(0.25)
    half = spacar.Table(np.linspace(0.0, period / 2, 101), np.zeros(101))
    with pytest.raises(spacar.InputError, match=r"the inputs table of \(1, 2\) covers"):
        floquet(pendulum(), period, inputs={(1, 2): half})


def test_a_free_pendulum_at_its_own_period_is_flagged():
    # Not driven: every small swing is periodic with the pendulum's own period, a family whose
    # multiplier along it is 1; the orbit found comes with a warning.
    m = pendulum()
    m.fix(1, 2)
    with pytest.warns(RuntimeWarning, match="multiplier is 1"):
        periodic_orbit(m, 2 * np.pi * np.sqrt(L / G), q=[0.3])
