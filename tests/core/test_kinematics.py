"""The general path's kinematics (cpp/src/kinematics/kinematics.cpp): Newton on the positions,
velocities and accelerations of a rigid slider-crank against its closed form."""
import numpy as np

import spacar

R, L, OMEGA = 0.15, 0.35, 1.5  # crank, connecting rod, crank speed


def slider_crank(n_out=20, t_end=2.0):
    """Crank PLBEAM 1 (nodes 1, 3) turned by INPUTX 2 at OMEGA, rod PLBEAM 2 (nodes 3, 6; its own
    orientation nodes: pinned) to the slider node 6 on the x axis: a kinematic analysis, no
    degrees of freedom."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 3, 5, 6, 7)
    m.fix(1)
    m.fix(6, 2)
    m.x(3, R, 0.0)
    m.x(6, R + L, 0.0)
    m.inputx(2, 1)
    m.xd(2, 1, OMEGA)
    m.timestep(n_out, t_end)
    m.epskin(1e-12)
    return m


def closed_form(t):
    """Slider position, velocity and acceleration: x = R cos θ + √(L² − R² sin² θ), θ = ω t."""
    th = OMEGA * t
    s = np.sqrt(L**2 - (R * np.sin(th)) ** 2)
    x = R * np.cos(th) + s
    dx_dth = -R * np.sin(th) - R**2 * np.sin(th) * np.cos(th) / s
    d2x_dth2 = (-R * np.cos(th) - R**2 * np.cos(2 * th) / s
                - (R**2 * np.sin(th) * np.cos(th)) ** 2 / s**3)
    return x, OMEGA * dx_dth, OMEGA**2 * d2x_dth2


def test_slider_crank_positions_velocities_accelerations_are_the_closed_form():
    res = spacar.simulate(slider_crank(), progress=False)
    slider = res.node(6)
    x, v, a = closed_form(res.t)
    np.testing.assert_allclose(slider.x[:, 0], x, atol=1e-11)
    np.testing.assert_allclose(slider.xd[:, 0], v, atol=1e-10)
    np.testing.assert_allclose(slider.xdd[:, 0], a, atol=1e-9)
    np.testing.assert_allclose(res.node(6).x[:, 1], 0.0, atol=1e-14)


def test_rigid_links_keep_their_lengths():
    res = spacar.simulate(slider_crank(), progress=False)
    rod = res.node(6).x - res.node(3).x
    np.testing.assert_allclose(np.hypot(rod[:, 0], rod[:, 1]), L, rtol=1e-12)
    np.testing.assert_allclose(np.hypot(*res.node(3).x.T), R, rtol=1e-12)
