"""spacar.transfer and spacar.transfer_path (issue 40): the first- and second-order transfer
functions DF, D2F of the inputs and DOFs, against independent references: the implicit
derivatives of a four-bar's loop-closure (Freudenstein) equations, the closed-form velocity and
acceleration ratios of a slider-crank, and central differences of DF on a two-DOF five-bar."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar.compare import models

CRANK = ("x", 11, 1)


def driven_four_bar():
    """The four-bar of spacar.compare.models with its crank driven (INPUTX on BETA 11 at 2 rad/s)."""
    m = models.four_bar()
    m.apply("INPUTX", 11, 1)
    m.timestep(36, 3.0)
    return m


def loop_derivatives(tf):
    """(θ3', θ4', θ3'', θ4'') of the coupler and rocker angles over the crank angle from the
    loop-closure equations a cos θ2 + b cos θ3 − d − c cos θ4 = 0, a sin θ2 + b sin θ3 − c sin θ4 = 0
    differentiated implicitly, at the transfer's configuration."""
    x = dict(zip(tf.coordinate_labels, tf.x))
    p1, p2, p3, p4 = (np.zeros(2), np.array([x[(2, 1)], x[(2, 2)]]), np.array([x[(3, 1)], x[(3, 2)]]),
                      np.array([2.5, 0.0]))
    a, b, c = 1.0, np.hypot(2.0, 0.5), np.hypot(0.5, 1.5)
    t2, t3, t4 = (np.arctan2(*(q - p)[::-1]) for p, q in ((p1, p2), (p2, p3), (p4, p3)))
    J = np.array([[-b * np.sin(t3), c * np.sin(t4)], [b * np.cos(t3), -c * np.cos(t4)]])
    first = -np.linalg.solve(J, [-a * np.sin(t2), a * np.cos(t2)])
    second = -np.linalg.solve(J, [-a * np.cos(t2) - b * np.cos(t3) * first[0] ** 2 + c * np.cos(t4) * first[1] ** 2,
                                  -a * np.sin(t2) - b * np.sin(t3) * first[0] ** 2 + c * np.sin(t4) * first[1] ** 2])
    return first, second


def test_four_bar_transfer_functions_are_freudenstein_s_over_a_cycle():
    """DF and D2F of the coupler's and rocker's rotations (BETA 21, 31) per crank angle equal the
    implicit derivatives of the loop-closure equations to 1e-10 at every 10° of the crank's turn
    (the mechanism needs no masses: the kinematic analysis alone)."""
    model = driven_four_bar()
    path = spacar.transfer_path(model, steps=36)
    assert path.q_labels == [CRANK] and path.is_input == [True]
    assert path.q[-1, 0] == pytest.approx(6.0) and path.D2F.shape == (37, 14, 1, 1)
    for k in range(len(path.t)):
        tf = path.at(k)
        first, second = loop_derivatives(tf)
        assert tf.ratio((21, 1), CRANK) == pytest.approx(first[0], abs=1e-10)
        assert tf.ratio((31, 1), CRANK) == pytest.approx(first[1], abs=1e-10)
        assert tf.second((21, 1), CRANK) == pytest.approx(second[0], abs=1e-10)
        assert tf.second((31, 1), CRANK) == pytest.approx(second[1], abs=1e-10)
    assert model.current_time == 0.0  # the model is not changed
    one = spacar.transfer(model)
    np.testing.assert_allclose(one.DF, path.DF[0], rtol=0, atol=1e-14)


def rigid_slider_crank(r=0.15, length=0.3):
    m = spacar.Model()
    m.plbeam(1, 1, 11, 2, 12)        # crank
    m.plbeam(2, 2, 21, 3, 22)        # rod
    m.x(1, 0.0, 0.0)
    m.x(2, r, 0.0)
    m.x(3, r + length, 0.0)
    m.fix(1)
    m.fix(3, 2)                      # the slider on the x axis
    m.apply("INPUTX", 11, 1)
    m.xd(11, 1, 1.0)
    m.timestep(24, 2 * np.pi)
    return m


def test_slider_crank_velocity_and_acceleration_ratios_are_the_closed_form():
    r, length = 0.15, 0.3
    path = spacar.transfer_path(rigid_slider_crank(r, length), steps=24)
    theta = path.q[:, 0]
    root = np.sqrt(length**2 - (r * np.sin(theta)) ** 2)
    velocity = -r * np.sin(theta) - r**2 * np.sin(theta) * np.cos(theta) / root
    acceleration = (-r * np.cos(theta) - r**2 * np.cos(2 * theta) / root
                    - r**4 * (np.sin(theta) * np.cos(theta)) ** 2 / root**3)
    np.testing.assert_allclose(path.ratio((3, 1), CRANK), velocity, rtol=0, atol=1e-12)
    np.testing.assert_allclose(path.second((3, 1), CRANK), acceleration, rtol=0, atol=1e-12)


def five_bar():
    """Two cranks from the ground pivots (0, 0) and (2, 0), both rotations DOFs, joined by two
    links at node 3: two degrees of freedom, no masses."""
    m = spacar.Model()
    m.plbeam(1, 1, 11, 2, 12)
    m.plbeam(2, 2, 21, 3, 22)
    m.plbeam(3, 4, 31, 5, 32)
    m.plbeam(4, 5, 41, 3, 42)
    for node, xy in ((1, (0.0, 0.0)), (2, (0.0, 1.0)), (3, (1.0, 2.0)), (4, (2.0, 0.0)), (5, (2.0, 1.0))):
        m.x(node, *xy)
    m.fix(1)
    m.fix(4)
    m.dynx(11, 1)
    m.dynx(31, 1)
    m.timestep(1, 1.0)
    return m


def test_five_bar_second_order_transfer_is_the_derivative_of_the_first():
    """A two-DOF five-bar away from its assembled configuration: D2F is symmetric and equals
    central differences of DF in each DOF to 1e-7; DF equals differences of the positions."""
    model = five_bar()
    q = np.array([0.3, -0.2])
    tf = spacar.transfer(model, at=(0.0, q))
    assert tf.q_labels == [("x", 11, 1), ("x", 31, 1)] and tf.is_input == [False, False]
    np.testing.assert_allclose(tf.D2F, np.swapaxes(tf.D2F, 1, 2), rtol=0, atol=1e-14)
    h = 1e-5
    for j in range(2):
        step = np.eye(2)[j] * h
        plus, minus = spacar.transfer(model, at=(0.0, q + step)), spacar.transfer(model, at=(0.0, q - step))
        np.testing.assert_allclose((plus.DF - minus.DF) / (2 * h), tf.D2F[:, :, j], rtol=0, atol=1e-7)
        np.testing.assert_allclose((plus.DFe - minus.DFe) / (2 * h), tf.D2Fe[:, :, j], rtol=0, atol=1e-7)
        np.testing.assert_allclose((plus.x - minus.x) / (2 * h), tf.DF[:, j], rtol=0, atol=1e-7)


def test_bad_requests_are_input_errors():
    model = driven_four_bar()
    with pytest.raises(spacar.InputError, match="model must be a spacar.Model"):
        spacar.transfer(42)
    with pytest.raises(spacar.InputError, match="at=.t, q. needs a finite time and 0 finite DOF values"):
        spacar.transfer(model, at=(0.0, [1.0]))
    with pytest.raises(spacar.InputError, match="steps must be a whole number"):
        spacar.transfer_path(model, steps=0)
    with pytest.raises(spacar.InputError, match="continuation steps from the model's configuration"):
        spacar.transfer(model, at=(1e300, []))
    rigid = spacar.Model()  # nothing moves: empty transfer functions
    rigid.plbeam(1, 1, 2, 3, 4)
    rigid.x(3, 1.0, 0.0)
    rigid.fix(1)
    rigid.fix(2)
    empty = spacar.transfer(rigid)
    assert empty.DF.shape == (6, 0) and empty.D2F.shape == (6, 0, 0) and empty.q_labels == []
    tf = spacar.transfer(model)
    with pytest.raises(spacar.InputError, match="is not an input or degree of freedom"):
        tf.ratio((3, 1), ("x", 3, 1))
    with pytest.raises(spacar.InputError, match="node 99 has no coordinate 1"):
        tf.ratio((99, 1), CRANK)
