"""The general path's equations of motion (cpp/src/kinematics/dynamics.cpp): a rigid pendulum of
large amplitude against scipy's integration of θ̈ = −(g/L) sin θ, and the tension of its rod (a
reaction stress) against the closed form M (L θ̇² + g cos θ)."""
import numpy as np
from scipy.integrate import solve_ivp

import spacar

L, M, G, THETA0 = 0.8, 1.3, 9.81, 2.0  # θ from the downward vertical


def pendulum(t_end=1.0, n_out=20):
    """PLBEAM 1 from the fixed pin (node 1) to the mass at node 3, the rotation of its orientation
    node 2 from the initial geometry the degree of freedom: θ = THETA0 + x(2)."""
    beta0 = THETA0 - np.pi / 2
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.fix(1)
    m.x(3, L * np.cos(beta0), L * np.sin(beta0))
    m.dynx(2, 1)
    m.mass(3, M)
    m.gravity(0.0, -G)
    m.forcemode(2)
    m.timestep(n_out, t_end)
    m.epsint(1e-11)
    m.epsind(1e-11)
    return m


def reference(t):
    sol = solve_ivp(lambda s, y: [y[1], -G / L * np.sin(y[0])], (0.0, t[-1]), [THETA0, 0.0], t_eval=t,
                    method="DOP853", rtol=1e-13, atol=1e-13)
    return sol.y


def test_large_swing_follows_the_pendulum_equation():
    res = spacar.simulate(pendulum(), method="dop853", progress=False)
    theta, omega = reference(res.t)
    beta = res.node(2)
    np.testing.assert_allclose(beta.x[:, 0], theta - THETA0, atol=1e-8)
    np.testing.assert_allclose(beta.xd[:, 0], omega, atol=1e-8)
    np.testing.assert_allclose(beta.xdd[:, 0], -G / L * np.sin(theta), atol=1e-7)


def test_rod_tension_is_the_centripetal_and_gravity_force():
    res = spacar.simulate(pendulum(), method="dop853", progress=False)
    theta, omega = reference(res.t)
    tension = M * (L * omega**2 + G * np.cos(theta))
    # σ of the elongation is the rod's axial force (positive in tension)
    np.testing.assert_allclose(res.element(1).sigma[:, 0], tension, rtol=1e-7, atol=1e-7)
