"""A digital PD controller on a pendulum (spacar.Controller, zero-order hold) against independent
references: the analytic closed-loop second-order system (fast sampling) and scipy.signal's
zero-order-hold discretization of the linearized plant (slow sampling, exact at the samples)."""

import numpy as np
import pytest
from scipy.signal import cont2discrete

import spacar

M, L, G = 1.0, 1.0, 9.81
KP, KD = 20.0, 3.0
W0 = 1e-4  # initial angular velocity [rad/s]: angles of 2e-5 rad, sin θ = θ to 7e-11


def pendulum(t_end, n_out):
    """A rigid PLBEAM hanging from the fixed node 1, a point mass at its tip node 3, its rotation
    x(2,1) the DOF, started at the vertical with angular velocity W0; the controller's torque
    acts on x(2,1)."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.x(3, 0.0, -L)
    m.fix(1)
    m.mass(3, M)
    m.gravity(0.0, -G)
    m.dynx(2, 1)
    m.xd(2, 1, W0)
    m.timestep(n_out, t_end)
    m.epsint(1e-11)
    m.epsind(1e-11)
    m.epskin(1e-13)
    return m


def pd(t, y):
    return [-KP * y[0] - KD * y[1]]


def controller(rate):
    return spacar.Controller(pd, rate=rate, sensors=[("x", 2, 1), ("xd", 2, 1)], actuators=[(2, 1)])


def test_fast_sampled_pd_follows_the_analytic_closed_loop():
    # J θ̈ + Kd θ̇ + (m g L + Kp) θ = 0, J = m L²: θ = W0/ωd e^(−ζ ωn t) sin ωd t. The hold delays the
    # control by half a sample on average: the error is first order in the sample period.
    J = M * L**2
    wn = np.sqrt((M * G * L + KP) / J)
    zeta = KD / (2 * J * wn)
    wd = wn * np.sqrt(1 - zeta**2)
    runs = {rate: spacar.simulate(pendulum(2.0, 200), controller=controller(rate), progress=False)
            for rate in (250.0, 500.0)}
    t = runs[250.0].t
    theta = W0 / wd * np.exp(-zeta * wn * t) * np.sin(wd * t)
    angle = {rate: res.x[:, res.coordinate_index(2, 1)] for rate, res in runs.items()}
    errors = [np.abs(angle[rate] - theta).max() / (W0 / wd) for rate in (250.0, 500.0)]
    assert errors[1] < 3e-3  # of the amplitude (measured 5.1e-3 and 2.6e-3)
    assert errors[1] == pytest.approx(errors[0] / 2, rel=0.02)  # first order in 1/rate
    # Richardson: the limit of zero sample period is the continuous closed loop.
    limit = 2 * angle[500.0] - angle[250.0]
    assert np.abs(limit - theta).max() < 5e-5 * W0 / wd  # O((ωn Ts)²); measured 2.0e-5


def test_slow_sampled_pd_equals_the_zoh_discretization():
    # At 20 Hz (ωn Ts = 0.27) the sampled loop is far from the continuous one, but at the samples
    # it is exactly the ZOH discretization of the plant closed by u_k = −K x_k.
    rate = 20.0
    ctrl = controller(rate)
    spacar.simulate(pendulum(2.0, 40), controller=ctrl, progress=False)
    J = M * L**2
    A = np.array([[0.0, 1.0], [-M * G * L / J, 0.0]])
    B = np.array([[0.0], [1.0 / J]])
    Ad, Bd, *_ = cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), 1.0 / rate, method="zoh")
    K = np.array([[KP, KD]])
    x = np.array([0.0, W0])
    ref = []
    for _ in range(len(ctrl.log["t"])):
        ref.append(x)
        x = (Ad - Bd @ K) @ x
    ref = np.array(ref)
    np.testing.assert_allclose(ctrl.log["t"], np.arange(len(ref)) / rate, rtol=0, atol=1e-12)
    assert len(ref) == 40  # samples at 0, 0.05, ..., 1.95 (none at the block end)
    for c in range(2):
        np.testing.assert_allclose(ctrl.log["sensors"][:, c], ref[:, c], rtol=0, atol=1e-8 * np.abs(ref[:, c]).max())
    np.testing.assert_allclose(ctrl.log["actuators"][:, 0], -(ref @ K.T)[:, 0], rtol=0, atol=1e-8 * KP * W0)


def test_controller_errors_are_clear():
    with pytest.raises(spacar.InputError, match="rate"):
        spacar.Controller(pd, rate=0, sensors=[], actuators=[(2, 1)])
    with pytest.raises(spacar.InputError, match="names no coordinate"):
        spacar.simulate(pendulum(0.1, 2), controller=spacar.Controller(pd, 10, [("x", 9, 1)], [(2, 1)]),
                        progress=False)
    bad = spacar.Controller(lambda t, y: [1.0, 2.0], 10, [("x", 2, 1)], [(2, 1)])
    with pytest.raises(spacar.InputError, match="must return 1 finite number"):
        spacar.simulate(pendulum(0.1, 2), controller=bad, progress=False)
