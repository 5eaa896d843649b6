"""method="auto" switching back from Radau to DOP853 on a mechanism whose stiffness goes within a
block: a pendulum creeping down against a strong damper whose lever arm vanishes at the bottom.

A rigid bar of length R turns about the pivot (node 1) with a unit mass at its tip (node 3), pulled
down by a constant force F, starting horizontal at rest. A PLTRUSS damper (no stiffness, EDAMPP)
joins the tip to an anchor a distance D below the pendulum's lowest point. Its damping on the
angle θ is c (∂l/∂θ)², with ∂l/∂θ = R (R + D) sin φ / l (φ the angle from the vertical), so the
eigenvalue −c (∂l/∂θ)²/J is about −2000 s⁻¹ when horizontal (stiff: the pendulum creeps) and
vanishes at the bottom, where the pendulum swings freely at ω = √(F/(mR)) = 10 rad/s with a
small amplitude. Reference: the same one-degree-of-freedom equation, J θ̈ = −F R cos θ −
c (∂l/∂θ)² θ̇, by SciPy's LSODA (Adams/BDF with its own switching) at rtol 1e-11.
"""
from __future__ import annotations

import numpy as np
import pytest

import spacar

R, D, F, C = 1.0, 1.0, 100.0, 2500.0      # m, m, N, N s/m (σ = C·l̇)
L0 = np.hypot(R, R + D)                   # initial length of the damper
T_END, N_OUT = 60.0, 60


def pendulum(eps=1e-6):
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)              # rigid bar, pivot 1, tip 3
    m.x(3, R, 0.0)
    m.pltruss(2, 3, 5)                   # the damper, to the anchor 5
    m.x(5, 0.0, -(R + D))
    m.plhinge(3, 6, 2)                   # the angle θ against the fixed BETA node 6: the DOF
    m.fix(1)
    m.fix(5)
    m.fix(6)
    m.dyne(3, 1)
    m.rlse(2)
    m.edampp(2, C * L0)                  # σ = (EDAMPP/l0) l̇
    m.mass(3, 1.0)
    m.force(3, 0.0, -F)
    m.timestep(N_OUT, T_END)
    m.apply("EPSINT", eps)
    m.apply("EPSIND", eps)
    return m


def lever(theta):
    """∂l/∂θ of the damper."""
    p = R * np.array([np.cos(theta), np.sin(theta)])
    dp = R * np.array([-np.sin(theta), np.cos(theta)])
    rel = p - np.array([0.0, -(R + D)])
    return rel @ dp / np.linalg.norm(rel)


@pytest.fixture(scope="module")
def reference():
    from scipy.integrate import solve_ivp

    def rhs(_t, y):
        theta, omega = y
        return [omega, -F * R * np.cos(theta) - C * lever(theta) ** 2 * omega]   # J = m R² = 1

    t = np.linspace(0.0, T_END, N_OUT + 1)
    sol = solve_ivp(rhs, (0.0, T_END), [0.0, 0.0], method="LSODA", t_eval=t, rtol=1e-11,
                    atol=1e-12)
    assert sol.success
    return sol.y


@pytest.fixture(scope="module")
def runs():
    return {m: spacar.simulate(pendulum(), method=m, progress=False) for m in ("auto", "radau5", "dop853")}


def test_auto_goes_to_radau_and_back_to_dop853(runs, reference):
    res = runs["auto"]
    sw = res.stats["switches"]
    assert [s[1:] for s in sw] == [("dop853", "radau5"), ("radau5", "dop853")], res.stats["method"]
    t_stiff, t_back = sw[0][0], sw[1][0]
    assert t_stiff < 1.0                      # the creeping start is detected at once
    # Back on DOP853 once the damper's lever arm has gone: its eigenvalue then is below 1 % of the
    # initial one (measured: switch at t ≈ 40 s, when the pendulum has reached the bottom).
    theta_back = np.interp(t_back, res.t, reference[0])
    assert C * lever(theta_back) ** 2 < 0.01 * C * lever(0.0) ** 2
    assert res.stats["method"].startswith("auto: dop853→radau5")
    # Far cheaper than DOP853 throughout (measured 408 against 12 344 steps).
    assert res.stats["steps"] < runs["dop853"].stats["steps"] / 5


@pytest.mark.parametrize("method", ["auto", "radau5", "dop853"])
def test_pendulum_against_reference(runs, reference, method):
    res = runs[method]
    theta, omega = res.coordinate(2, 1), res.coordinate(2, 1, "XD")
    # Measured: auto 1.8e-6 rad / 2.4e-6 rad/s, radau5 2.9e-6 / 4.1e-6, dop853 3.0e-6 / 2.3e-5.
    np.testing.assert_allclose(theta, reference[0], rtol=0, atol=2e-5)
    np.testing.assert_allclose(omega, reference[1], rtol=0, atol=1e-4)
    np.testing.assert_allclose(res.deformation(3, 1), theta, rtol=0, atol=1e-12)
    # The creep ended at the bottom (θ = −π/2), where the pendulum swings with a small amplitude.
    assert abs(theta[-1] + np.pi / 2) < 0.05
